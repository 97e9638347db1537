// `tessera bench --fcc-out DIR`: the FCC lattice's quality figures. Marschner-Lobb
// (fM = 6, alpha = 0.25) on the Cartesian grid (trilinear) and on the FCC
// lattice (box spline, same and half sample count), at 41^3 and 64^3: RMS
// error of the reconstructed signal along the rays and at random points
// (CPU twins of the GPU reconstructions), and GPU images with a soft and an
// isosurface-like TF against the CPU reference of the analytic signal; then
// ch2 resampled onto FCC against the reference of the Cartesian original.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <vector>

#include "bench/BenchFcc.h"
#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/Procedural.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/lattice/BoxSplineReconstruction.h"
#include "tessera/lattice/FccResampling.h"
#include "tessera/lattice/MarschnerLobb.h"
#include "tessera/layout/FccLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/Reconstruction.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

Camera obliqueCamera(const Volume& v) {
  return Camera::framing(v, 30, 50);  // from above: the rings of the signal show
}

Image gpuImage(gpu::GlContext& context, const gpu::DeviceLimits& limits, const Volume& box,
               const layout::Layout& layout, const TransferFunction& tf, const Camera& cam,
               int size) {
  const render::TechniqueOptions options{.imageSize = {size, size}};
  auto caster = render::TechniqueRegistry::global().create(
      "raycast",
      {.context = context, .limits = limits, .volume = box, .layout = &layout, .options = options});
  caster->setTransferFunction(tf);
  return caster->renderImage(cam, {}, size, size);
}

struct Row {
  std::string label;
  std::uint64_t samples;
  std::unique_ptr<Reconstruction> cpu;
  std::unique_ptr<layout::Layout> gpu;
  std::string file;
};

void marschnerLobb(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                   const std::filesystem::path& dir, int size) {
  std::printf(
      "Marschner-Lobb (fM = 6, alpha = 0.25), values in [0,1]. RMS: reconstructed signal vs the "
      "analytic one at the ray caster's samples (%dx%d rays, azimuth 30, elevation 50) and at "
      "40000 random "
      "points; PSNR: the GPU image vs the CPU reference of the analytic signal (%dx%d).\n\n"
      "| lattice, reconstruction | samples | RMS along rays | RMS random | PSNR soft TF | PSNR "
      "iso TF |\n|---|---:|---:|---:|---:|---:|\n",
      128, 128, size, size);
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> d(0.0, 1.0);
  std::vector<glm::dvec3> random(40000);
  for (glm::dvec3& p : random) p = {d(rng), d(rng), d(rng)};
  for (const int n : {41, 64}) {
    const Volume cartesian = makeMarschnerLobb(glm::ivec3(n));
    const Camera cam = obliqueCamera(cartesian);
    const std::vector<glm::dvec3> rays = lattice::raySamplePositions(cartesian, cam, 128);
    std::vector<Row> rows;
    rows.push_back({"Cartesian " + std::to_string(n) + "^3, trilinear", cartesian.voxelCount(),
                    std::make_unique<TrilinearReconstruction>(cartesian),
                    layout::Texture3DLayout::create(cartesian, limits, context.ledger()),
                    "fcc-ml" + std::to_string(n) + "-cartesian"});
    for (const lattice::FccDensity density :
         {lattice::FccDensity::Same, lattice::FccDensity::Half}) {
      lattice::FccVolume fcc = lattice::makeMarschnerLobbFcc(cartesian, density);
      const std::string dn(lattice::fccDensityName(density));
      Row r{"FCC " + dn + " (" + std::to_string(fcc.gridDims().x) + "^3 grid), box spline",
            fcc.pointCount(), std::make_unique<lattice::BoxSplineReconstruction>(fcc), nullptr,
            "fcc-ml" + std::to_string(n) + "-fcc-" + dn};
      r.gpu = layout::FccLayout::create(std::move(fcc), limits, context.ledger(),
                                        layout::FccLayout::layoutName(density));
      rows.push_back(std::move(r));
    }
    std::vector<Image> truths;
    for (const TransferFunction& tf :
         {lattice::marschnerLobbSoftTf(), lattice::marschnerLobbIsoTf()}) {
      truths.push_back(renderReference(cartesian, lattice::MarschnerLobbSignal(cartesian.dims()),
                                       tf, cam, {}, size, size));
      truths.back().writePng(dir / ("fcc-ml" + std::to_string(n) + "-truth-" + tf.name + ".png"));
    }
    for (const Row& r : rows) {
      double db[2];
      int i = 0;
      for (const TransferFunction& tf :
           {lattice::marschnerLobbSoftTf(), lattice::marschnerLobbIsoTf()}) {
        const Image img = gpuImage(context, limits, cartesian, *r.gpu, tf, cam, size);
        img.writePng(dir / (r.file + "-" + tf.name + ".png"));
        db[i] = psnr(img, truths[static_cast<std::size_t>(i)]);
        ++i;
      }
      std::printf("| %s | %llu | %.5f | %.5f | %.2f dB | %.2f dB |\n", r.label.c_str(),
                  static_cast<unsigned long long>(r.samples),
                  lattice::marschnerLobbRms(*r.cpu, rays, cartesian.dims()),
                  lattice::marschnerLobbRms(*r.cpu, random, cartesian.dims()), db[0], db[1]);
    }
  }
}

void ch2(gpu::GlContext& context, const gpu::DeviceLimits& limits, const std::filesystem::path& dir,
         int size) {
  const char* path = "/usr/share/mricron/templates/ch2.nii.gz";
  if (!std::filesystem::exists(path)) {
    std::printf("\n(ch2 skipped: %s not installed)\n", path);
    return;
  }
  const Volume original = readVolume(path);
  const TransferFunction tf = TransferFunction::preset("mr-default");
  const Camera cam = Camera::framing(original, 30, 15);
  const Image ref = renderReference(original, tf, cam, {}, size, size);
  ref.writePng(dir / "fcc-ch2-reference.png");
  std::printf(
      "\nch2 (181x217x181 u8, %s TF, %dx%d): GPU images vs the CPU (trilinear) reference of the "
      "original\n\n| volume | lattice points | texture | PSNR | SSIM |\n|---|---:|---|---:|---:|\n",
      tf.name.c_str(), size, size);
  struct Case {
    std::string label, file;
    std::unique_ptr<layout::Layout> layout;
    std::uint64_t points;
  };
  std::vector<Case> cases;
  cases.push_back({"Cartesian original, trilinear", "fcc-ch2-cartesian",
                   layout::Texture3DLayout::create(original, limits, context.ledger()),
                   original.voxelCount()});
  for (const lattice::FccDensity density : {lattice::FccDensity::Half, lattice::FccDensity::Same}) {
    auto l = layout::FccLayout::resample(original, density, limits, context.ledger());
    const std::uint64_t points = l->lattice().pointCount();
    cases.push_back({"FCC " + std::string(lattice::fccDensityName(density)) +
                         " (cubic B-spline resampling, quasi-interpolated), box spline",
                     "fcc-ch2-fcc-" + std::string(lattice::fccDensityName(density)), std::move(l),
                     points});
  }
  for (const Case& c : cases) {
    const Image img = gpuImage(context, limits, original, *c.layout, tf, cam, size);
    img.writePng(dir / (c.file + ".png"));
    const auto& t = c.layout->plan().textures.at(0);
    std::printf("| %s | %llu | %dx%dx%d %s, %s | %.2f dB | %.5f |\n", c.label.c_str(),
                static_cast<unsigned long long>(c.points), t.size.x, t.size.y, t.size.z,
                t.format.c_str(), formatBytes(c.layout->textureBytes()).c_str(), psnr(img, ref),
                ssim(img, ref));
  }
}

}  // namespace

void runFccQuality(const std::string& outDir, int size) {
  const std::filesystem::path dir(outDir);
  std::filesystem::create_directories(dir);
  auto context = gpu::GlContext::createHeadless();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context->caps());
  if (limits.api != gpu::ApiLevel::Gles3) {
    throw InputError("bench --fcc-out needs an OpenGL ES 3 context for the box spline");
  }
  marschnerLobb(*context, limits, dir, size);
  ch2(*context, limits, dir, std::max(size, 384));
  std::printf("\nimages: %s/fcc-*.png\n", dir.string().c_str());
}

}  // namespace tessera::app
