#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "app/Commands.h"
#include "app/RenderJob.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/VolumeReader.h"

namespace tessera::app {

namespace {

struct BenchOptions {
  std::string file;
  std::string size = "512x512";
  int frames = 36;
  double rotate = 10.0;
  double step = 0.5;
  std::string tf = "bench";
  bool json = false;
};

double samplesPerRay(const RenderResult& r) {
  return r.referenceRays
             ? static_cast<double>(r.referenceSamples) / static_cast<double>(r.referenceRays)
             : 0.0;
}

struct Variant {
  const char* name;
  int skipBlock;
  double ert;
};

// The ray-casting benchmark of the Foundation issue: ch2 at 512x512, 36
// frames rotating 10 degrees, 0.5-voxel steps, TF "bench"; run with the
// accelerations switched on one at a time to show where the time goes.
void runBench(const BenchOptions& o) {
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  const Volume volume = readVolume(spec);
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  auto context = gpu::GlContext::createHeadless();
  RenderRequest req;
  parseSize(o.size, req.width, req.height);
  req.repeat = o.frames;
  req.rotateDeg = o.rotate;
  req.settings.stepVoxels = o.step;
  req.reference = true;

  const Variant variants[] = {{"plain (no ERT, no skipping)", 0, 2.0},
                              {"early ray termination", 0, 0.99},
                              {"ERT + empty-space skipping 8^3", 8, 0.99},
                              {"ERT + empty-space skipping 4^3", 4, 0.99},
                              {"ERT + empty-space skipping 16^3", 16, 0.99}};
  nlohmann::json rows = nlohmann::json::array();
  if (!o.json) {
    std::printf("ray casting %s at %dx%d, %d frames rotating %g deg, step %g voxel, TF %s\n",
                spec.c_str(), req.width, req.height, o.frames, o.rotate, o.step, o.tf.c_str());
    std::printf("GL: %s\n\n", context->caps().renderer.c_str());
    std::printf(
        "| variant | median ms | min ms | max ms | samples/ray (frame 0) | PSNR dB (frame 0) | "
        "SSIM "
        "|\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|\n");
  }
  for (const Variant& v : variants) {
    req.skipBlock = v.skipBlock;
    req.settings.ertThreshold = v.ert;
    const RenderResult r = runRender(*context, volume, tf, req);
    // Each variant is compared with the reference of its own semantics
    // (without ERT the reference also runs to the end of the ray).
    if (!o.json) {
      // Samples per ray of the reference are what the GPU takes without
      // skipping; with skipping it takes the same samples minus the skipped ones.
      std::printf("| %s | %.1f | %.1f | %.1f | %.0f | %.2f | %.5f |\n", v.name, r.median(), r.min(),
                  r.max(), samplesPerRay(r), *r.psnrDb, *r.ssim);
      std::fflush(stdout);
    }
    rows.push_back({{"variant", v.name},
                    {"skip_block", v.skipBlock},
                    {"ert", v.ert},
                    {"ms_median", r.median()},
                    {"ms_min", r.min()},
                    {"ms_max", r.max()},
                    {"psnr_db", *r.psnrDb},
                    {"reference_samples", r.referenceSamples},
                    {"reference_rays", r.referenceRays},
                    {"ssim", *r.ssim},
                    {"frames", r.frameMs.size()},
                    {"texture_bytes", r.textureBytes}});
  }
  if (o.json) {
    nlohmann::json j;
    j["file"] = spec;
    j["width"] = req.width;
    j["height"] = req.height;
    j["gl_renderer"] = context->caps().renderer;
    j["rows"] = rows;
    std::printf("%s\n", j.dump(2).c_str());
  }
}

}  // namespace

void addBenchCommand(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand("bench",
                                     "Ray-casting benchmark: N rotating frames per acceleration "
                                     "variant, with PSNR vs the CPU reference");
  cmd->add_option("file", o->file, "Volume (default: ch2 or a phantom)");
  cmd->add_option("--size", o->size, "Image size WIDTHxHEIGHT")->capture_default_str();
  cmd->add_option("--frames", o->frames, "Frames per variant")->capture_default_str();
  cmd->add_option("--rotate", o->rotate, "Azimuth step per frame in degrees")
      ->capture_default_str();
  cmd->add_option("--step", o->step, "Sample distance in voxels")->capture_default_str();
  cmd->add_option("--tf", o->tf, "Transfer function preset or JSON file")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print JSON instead of a Markdown table");
  cmd->callback([o] { runBench(*o); });
}

}  // namespace tessera::app
