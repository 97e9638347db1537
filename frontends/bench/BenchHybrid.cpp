#include "bench/BenchHybrid.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/VolumeUpload.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceOverlay.h"
#include "tessera/render/HybridCompositor.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

// Saturated, semi-transparent hues over the MRI range: dark blue is the most
// opaque, pale yellow the brightest, so luminance is a poor opacity guess.
TransferFunction colouredTf() {
  return TransferFunction::fromPoints(
      "coloured",
      {
          {0.0, {0.0, 0.0, 0.0}},
          {0.15, {0.1, 0.15, 0.85}},
          {0.35, {0.85, 0.15, 0.1}},
          {0.6, {0.2, 0.8, 0.2}},
          {1.0, {1.0, 0.95, 0.5}},
      },
      {{0.0, 0.0}, {0.12, 0.0}, {0.2, 0.05}, {0.45, 0.02}, {1.0, 0.3}});
}

// The volume uploaded once as texture3d, which every technique shares.
struct Scene {
  gpu::GlContext& context;
  gpu::DeviceLimits limits;
  layout::VolumeUpload upload;
  const Volume& volume() const { return *upload.volume; }
};

// A technique of the registry on the scene's upload, with its TF, prepared.
std::unique_ptr<render::Technique> makeTechnique(const Scene& scene, const std::string& name,
                                                 const TransferFunction& tf,
                                                 const RenderSettings& settings) {
  const render::TechniqueOptions options;
  std::unique_ptr<render::Technique> t =
      render::TechniqueRegistry::global().create(name, {.context = scene.context,
                                                        .limits = scene.limits,
                                                        .volume = scene.volume(),
                                                        .layout = scene.upload.layout.get(),
                                                        .options = options});
  t->setTransferFunction(tf);
  Camera camera;
  camera.frame(scene.volume());
  t->prepare(camera, settings);
  return t;
}

std::string fmtDb(double db) {
  if (std::isinf(db)) return "identical";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f dB", db);
  return buf;
}

// Figure 2 as numbers: PSNR of each opacity method vs the ground truth.
nlohmann::json qualityTable(const Scene& scene, const HybridBenchOptions& o, bool print) {
  const Volume& volume = scene.volume();
  const int width = 480, height = 640;
  const render::OffscreenSize offscreen = render::OffscreenSize::ofSize(128, 128);
  struct Case {
    std::string name;
    TransferFunction tf;
    std::string overlays;
  };
  const std::vector<Case> cases{
      {"mr-default, box", TransferFunction::preset("mr-default"), "box"},
      {"mr-default, box+axes+roi", TransferFunction::preset("mr-default"), "box,axes,roi"},
      {"coloured, box", colouredTf(), "box"},
      {"coloured, box+axes+roi", colouredTf(), "box,axes,roi"}};
  Camera camera = Camera::framing(volume, 35, 20);
  camera.zoom = 0.8;  // the whole box in the portrait screen
  RenderSettings settings;
  settings.stepVoxels = o.step;
  render::HybridCompositor compositor(scene.context);
  std::vector<std::string> rowNames;
  for (auto m : render::allOverlayOpacities()) rowNames.push_back(render::overlayOpacityName(m));
  rowNames.push_back("lines on top, unattenuated");
  rowNames.push_back("alpha, volume at full resolution");
  std::map<std::string, std::vector<double>> rows;
  nlohmann::json j = nlohmann::json::array();
  for (const Case& c : cases) {
    const std::unique_ptr<render::Technique> caster =
        makeTechnique(scene, "raycast", c.tf, settings);
    compositor.setOverlayLines(
        render::overlayLines(volume, render::OverlayOptions::parse(c.overlays)));
    std::fprintf(stderr, "\rquality: %s ...          ", c.name.c_str());
    std::map<std::string, Image> images;
    for (auto m : render::allOverlayOpacities()) {
      compositor.render(*caster, camera, settings, volume.extent(), width, height, {offscreen, m});
      images[render::overlayOpacityName(m)] = compositor.readImage();
    }
    const Image lines = compositor.overlays().readColor();
    const Image truth = renderReferenceWithLines(volume, c.tf, camera, settings, width, height,
                                                 lines, compositor.overlays().readDistance());
    Image pasted = images["alpha"];
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (lines.pixel(x, y)[3]) std::copy_n(lines.pixel(x, y), 4, pasted.pixel(x, y));
    images["lines on top, unattenuated"] = pasted;
    compositor.render(*caster, camera, settings, volume.extent(), width, height,
                      {render::OffscreenSize::ofFactor(1.0), render::OverlayOpacity::Alpha});
    images["alpha, volume at full resolution"] = compositor.readImage();
    nlohmann::json jc{{"case", c.name}};
    for (const std::string& r : rowNames) {
      const double p = psnr(images[r], truth);
      rows[r].push_back(p);
      jc[r] = std::isinf(p) ? 999.0 : p;
    }
    j.push_back(jc);
    if (!o.outDir.empty() && c.overlays != "box") {
      std::filesystem::create_directories(o.outDir);
      const std::string stem = o.outDir + "/hybrid-" + c.tf.name + "-";
      truth.writePng(stem + "truth.png");
      for (auto m : render::allOverlayOpacities()) {
        images[render::overlayOpacityName(m)].writePng(stem + render::overlayOpacityName(m) +
                                                       ".png");
      }
      pasted.writePng(stem + "on-top.png");
    }
  }
  std::fprintf(stderr, "\r%*s\r", 60, "");
  if (print) {
    std::printf(
        "overlay opacity vs ground truth (CPU reference at full resolution, rays stop at the "
        "lines): %s, %dx%d screen, volume at %s, azimuth 35, elevation 20, zoom 0.8, step %g\n\n",
        o.file.empty() ? defaultVolumeSpec().c_str() : o.file.c_str(), width, height,
        offscreen.describe().c_str(), o.step);
    std::printf("| method |");
    for (const Case& c : cases) std::printf(" %s |", c.name.c_str());
    std::printf("\n|---|");
    for (std::size_t i = 0; i < cases.size(); ++i) std::printf("---:|");
    std::printf("\n");
    for (const std::string& r : rowNames) {
      std::printf("| %s |", r.c_str());
      for (double p : rows[r]) std::printf(" %s |", fmtDb(p).c_str());
      std::printf("\n");
    }
    std::printf("\n");
  }
  return j;
}

// Full resolution vs hybrid at several offscreen sizes, for each technique,
// frames interleaved so that a shared machine's load falls on all alike.
nlohmann::json speedTable(const Scene& scene, const HybridBenchOptions& o, bool print) {
  const Volume& volume = scene.volume();
  gpu::GlContext& context = scene.context;
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  RenderSettings settings;
  settings.stepVoxels = o.step;
  std::vector<std::unique_ptr<render::Technique>> techniques;
  for (const std::string& name : render::TechniqueRegistry::global().names()) {
    techniques.push_back(makeTechnique(scene, name, tf, settings));
  }
  render::HybridCompositor compositor(context);
  compositor.setOverlayLines(
      render::overlayLines(volume, render::OverlayOptions::parse("box,axes")));
  const std::vector<glm::ivec2> screens{{480, 640}, {1024, 768}};
  const std::vector<std::string> sizes{"full", "128x128", "256x256", "256x512"};
  Camera camera;
  camera.frame(volume);
  nlohmann::json j = nlohmann::json::array();
  if (print) {
    std::printf(
        "hybrid speed: %s, TF %s, step %g, overlays box+axes, opacity alpha, %d frames rotating "
        "%g deg, variants interleaved; GL %s\n\n",
        o.file.empty() ? defaultVolumeSpec().c_str() : o.file.c_str(), tf.name.c_str(), o.step,
        o.frames, o.rotate, context.caps().renderer.c_str());
    std::printf(
        "| technique | screen | volume target | median ms | min ms | speed-up vs full | volume ms "
        "| "
        "lines + composite ms | PSNR vs full (frame 0) |\n");
    std::printf("|---|---|---|---:|---:|---:|---:|---:|---:|\n");
  }
  for (const glm::ivec2 screen : screens) {
    std::map<std::string, std::vector<double>> ms, volMs, restMs;
    std::map<std::string, Image> first;
    std::map<std::string, glm::ivec2> target;
    for (int f = 0; f < o.frames + 1; ++f) {  // frame 0 warms up (allocations)
      Camera cam = camera;
      cam.azimuthDeg += f * o.rotate;
      for (const auto& t : techniques) {
        for (const std::string& size : sizes) {
          const std::string key = t->name() + " " + size;
          const auto t0 = std::chrono::steady_clock::now();
          compositor.render(*t, cam, settings, volume.extent(), screen.x, screen.y,
                            {render::OffscreenSize::parse(size), render::OverlayOpacity::Alpha});
          const double elapsed = msSince(t0);
          if (f == 0) {
            first[key] = compositor.readImage();
            target[key] = compositor.timings().rendered;
            continue;
          }
          ms[key].push_back(elapsed);
          volMs[key].push_back(compositor.timings().volumeMs);
          restMs[key].push_back(compositor.timings().overlayMs + compositor.timings().compositeMs);
        }
      }
      std::fprintf(stderr, "\rspeed %dx%d: frame %d/%d", screen.x, screen.y, f, o.frames);
    }
    std::fprintf(stderr, "\r%*s\r", 40, "");
    for (const auto& t : techniques) {
      const std::string fullKey = t->name() + " full";
      const double full = median(ms[fullKey]);
      for (const std::string& size : sizes) {
        const std::string key = t->name() + " " + size;
        const double med = median(ms[key]);
        const double p = psnr(first[key], first[fullKey]);
        const glm::ivec2 low = target[key];
        const std::string targetName =
            std::to_string(low.x) + "x" + std::to_string(low.y) + (size == "full" ? " (full)" : "");
        if (print) {
          std::printf("| %s | %dx%d | %s | %.1f | %.1f | %.2f | %.1f | %.1f | %s |\n",
                      t->name().c_str(), screen.x, screen.y, targetName.c_str(), med,
                      *std::min_element(ms[key].begin(), ms[key].end()), full / med,
                      median(volMs[key]), median(restMs[key]),
                      size == "full" ? "—" : fmtDb(p).c_str());
        }
        j.push_back({{"technique", t->name()},
                     {"screen", {screen.x, screen.y}},
                     {"offscreen", {low.x, low.y}},
                     {"ms_median", med},
                     {"frame_ms", ms[key]},
                     {"speedup", full / med},
                     {"psnr_vs_full", std::isinf(p) ? 999.0 : p}});
      }
    }
  }
  if (print) std::printf("\n");
  return j;
}

}  // namespace

void runHybridBench(const HybridBenchOptions& o) {
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  auto context = gpu::GlContext::createHeadless();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context->caps());
  const Scene scene{
      *context, limits,
      layout::uploadVolume(*context, limits, lod::InCoreVolumeSource(readVolume(spec)), {},
                           "texture3d")};
  nlohmann::json j;
  j["speed"] = speedTable(scene, o, !o.json);
  j["quality"] = qualityTable(scene, o, !o.json);
  if (o.json) {
    j["file"] = spec;
    j["gl_renderer"] = context->caps().renderer;
    std::printf("%s\n", j.dump(2).c_str());
  }
}

}  // namespace tessera::app
