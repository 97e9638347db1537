#include "bench/BenchFcc.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/lattice/FccResampling.h"
#include "tessera/lattice/MarschnerLobb.h"
#include "tessera/layout/FccLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/lod/Downsample.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

using Evaluation = layout::FccLayout::Evaluation;

struct Dataset {
  std::string name;
  Volume cartesian;
  // Marschner-Lobb is sampled on the lattice from its formula; the others
  // are resampled (cubic B-spline, quasi-interpolated).
  bool analytic = false;
};

std::vector<Dataset> datasets() {
  std::vector<Dataset> out;
  out.push_back({"Marschner-Lobb", makeMarschnerLobb(glm::ivec3(64)), true});
  out.push_back({"Shepp-Logan", makeSheppLogan(glm::ivec3(64)), false});
  const char* ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
  if (std::filesystem::exists(ch2)) {
    out.push_back({"ch2 / 3", lod::downsample(readVolume(ch2), glm::ivec3(3)), false});
  }
  return out;
}

lattice::FccVolume latticeOf(const Dataset& d, lattice::FccDensity density) {
  if (d.analytic) return lattice::makeMarschnerLobbFcc(d.cartesian, density);
  lattice::FccResampleOptions options;
  options.density = density;
  return lattice::resampleToFcc(d.cartesian, options);
}

struct Variant {
  std::string name;
  std::unique_ptr<layout::Layout> layout;
  std::unique_ptr<render::Technique> caster;
  std::vector<double> ms;
  double median() const { return tessera::median(ms); }
};

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

struct Run {
  std::vector<Variant> variants;  // trilinear, fcc same, fcc half, fetches only, arithmetic only
};

// Variants, in this order: trilinear; box spline same and half density
// from cube storage (5 fetches); the same from packed storage (16 fetches);
// the cost split of same/cubes.
Run benchDataset(gpu::GlContext& context, const gpu::DeviceLimits& limits, const Dataset& d,
                 const TransferFunction& tf, const FccBenchOptions& o, int width, int height) {
  using Storage = layout::FccLayout::Storage;
  Run run;
  run.variants.push_back({"trilinear",
                          layout::Texture3DLayout::create(d.cartesian, limits, context.ledger()),
                          {},
                          {}});
  const lattice::FccVolume same = latticeOf(d, lattice::FccDensity::Same);
  const lattice::FccVolume half = latticeOf(d, lattice::FccDensity::Half);
  for (const Storage storage : {Storage::Cubes, Storage::Packed}) {
    const std::string s = layout::FccLayout::storageName(storage);
    run.variants.push_back(
        {"same, " + s,
         layout::FccLayout::create(same, limits, context.ledger(), "fcc", storage),
         {},
         {}});
    run.variants.push_back(
        {"half, " + s,
         layout::FccLayout::create(half, limits, context.ledger(), "fcc-half", storage),
         {},
         {}});
  }
  for (const auto& [name, e] :
       {std::pair{"same, cubes, fetches only", Evaluation::FetchesOnly},
        std::pair{"same, cubes, weights only", Evaluation::ArithmeticOnly}}) {
    auto l = layout::FccLayout::create(same, limits, context.ledger(), "fcc", Storage::Cubes);
    l->setEvaluation(e);
    run.variants.push_back({name, std::move(l), {}, {}});
  }
  RenderSettings settings;
  settings.stepVoxels = o.step;
  Camera camera;
  camera.frame(d.cartesian);
  for (Variant& v : run.variants) {
    const render::TechniqueOptions options{.imageSize = {width, height}};
    v.caster = render::TechniqueRegistry::global().create("raycast", {.context = context,
                                                                      .limits = limits,
                                                                      .volume = d.cartesian,
                                                                      .layout = v.layout.get(),
                                                                      .options = options});
    v.caster->setTransferFunction(tf);
    v.caster->prepare(camera, settings);
  }
  for (int f = 0; f < o.frames; ++f) {
    Camera cam = camera;
    cam.azimuthDeg += f * o.rotate;
    for (Variant& v : run.variants) {
      const auto t0 = std::chrono::steady_clock::now();
      v.caster->render(cam, settings, width, height, 0.0);
      v.ms.push_back(msSince(t0));
    }
    if (!o.json) std::fprintf(stderr, "\r%s: frame %d/%d", d.name.c_str(), f + 1, o.frames);
  }
  if (!o.json) std::fprintf(stderr, "\r%*s\r", 40, "");
  return run;
}

std::string gridOf(const layout::Layout& l) {
  return dimsText(static_cast<const layout::FccLayout&>(l).lattice().gridDims());
}

std::string cell(const Variant& v, double base) {
  char text[96];
  std::snprintf(text, sizeof text, "%.1f (%.2f)", v.median(), v.median() / base);
  return text;
}

void printTables(const std::vector<Dataset>& sets, const std::vector<Run>& runs) {
  std::printf(
      "ms per frame (÷ trilinear). Cubes: 5 RGBA texelFetch per sample; packed: 16 texelFetch.\n\n"
      "| volume | Cartesian | trilinear | FCC same grid | box spline, cubes | box spline, packed "
      "| FCC half grid | box spline, cubes | box spline, packed |\n"
      "|---|---|---:|---|---:|---:|---|---:|---:|\n");
  // One row per volume, its variants and the trilinear median they are divided by.
  const auto eachVolume = [&](const auto& row) {
    for (std::size_t i = 0; i < sets.size(); ++i) {
      row(sets[i], runs[i].variants, runs[i].variants[0].median());
    }
  };
  eachVolume([](const Dataset& set, const auto& v, double base) {
    std::printf("| %s | %s %s | %.1f | %s | %s | %s | %s | %s | %s |\n", set.name.c_str(),
                dimsText(set.cartesian.dims()).c_str(),
                std::string(scalarTypeName(set.cartesian.type())).c_str(), base,
                gridOf(*v[1].layout).c_str(), cell(v[1], base).c_str(), cell(v[3], base).c_str(),
                gridOf(*v[2].layout).c_str(), cell(v[2], base).c_str(), cell(v[4], base).c_str());
  });
  std::printf(
      "\nWhere the box spline's time goes (same density, cubes; the split variants are not "
      "reconstructions), and the textures:\n\n| volume | trilinear | box spline | 5 fetches "
      "only | weights only | trilinear texture | cubes texture | packed texture |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|\n");
  eachVolume([](const Dataset& set, const auto& v, double base) {
    std::printf("| %s | %.1f | %s | %s | %s | %s | %s | %s |\n", set.name.c_str(), base,
                cell(v[1], base).c_str(), cell(v[5], base).c_str(), cell(v[6], base).c_str(),
                formatBytes(v[0].layout->textureBytes()).c_str(),
                formatBytes(v[1].layout->textureBytes()).c_str(),
                formatBytes(v[3].layout->textureBytes()).c_str());
  });
}

void printJson(const std::vector<Dataset>& sets, const std::vector<Run>& runs,
               const gpu::GlContext& context, int width, int height, const FccBenchOptions& o) {
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const double base = runs[i].variants[0].median();
    for (const Variant& v : runs[i].variants) {
      rows.push_back({{"volume", sets[i].name},
                      {"dims", dimsText(sets[i].cartesian.dims())},
                      {"variant", v.name},
                      {"layout", v.layout->name()},
                      {"ms_median", v.median()},
                      {"ratio_to_trilinear", v.median() / base},
                      {"texture_bytes", v.layout->textureBytes()},
                      {"frame_ms", v.ms}});
    }
  }
  nlohmann::json j;
  j["width"] = width;
  j["height"] = height;
  j["frames"] = o.frames;
  j["gl_renderer"] = context.caps().renderer;
  j["rows"] = rows;
  std::printf("%s\n", j.dump(2).c_str());
}

}  // namespace

void runFccBench(const FccBenchOptions& o) {
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  auto context = gpu::GlContext::createHeadless();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context->caps());
  if (limits.api != gpu::ApiLevel::Gles3) {
    throw InputError("bench --fcc needs an OpenGL ES 3 context for the box spline");
  }
  const std::vector<Dataset> sets = datasets();
  std::vector<Run> runs;
  for (const Dataset& d : sets) {
    runs.push_back(benchDataset(*context, limits, d, tf, o, width, height));
  }
  if (o.json) {
    printJson(sets, runs, *context, width, height, o);
    return;
  }
  std::printf(
      "FCC box spline vs Cartesian trilinear (Sarfaraz & Shaban 2015, Tables 1-2): ray casting "
      "at %dx%d, %d frames rotating %g deg, step %g voxel of the Cartesian grid, TF %s, ERT + "
      "8^3 skipping\nGL: %s; variants interleaved frame by frame, median ms per frame\n\n",
      width, height, o.frames, o.rotate, o.step, o.tf.c_str(), context->caps().renderer.c_str());
  printTables(sets, runs);
}

}  // namespace tessera::app
