#include "bench/BenchBrickWalk.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

// "u16:SPEC": the volume SPEC widened to 16 bits (v * 257 plus a smooth
// ramp of up to 255 along x), so that the bricks hold 16-bit texels and the
// low byte varies; anything else is read as it is.
Volume benchVolume(const std::string& spec) {
  if (spec.rfind("u16:", 0) != 0) return readVolume(spec);
  const Volume narrow = readVolume(spec.substr(4));
  const glm::ivec3 d = narrow.dims();
  Volume wide = Volume::allocate(d, ScalarType::U16, spec);
  wide.setSpacing(narrow.spacing());
  auto* out = wide.dataAs<std::uint16_t>();
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x) {
        const std::size_t i = narrow.index(x, y, z);
        const double ramp = 255.0 * x / std::max(1, d.x - 1);
        out[i] = static_cast<std::uint16_t>(
            std::min(65535.0, narrow.valueAtIndex(i) * 257.0 + std::floor(ramp)));
      }
    }
  }
  wide.invalidateRange();
  return wide;
}

std::vector<double> framesAfterFirst(const session::RenderResult& r) {
  return std::vector<double>(r.frameMs.begin() + 1, r.frameMs.end());
}

}  // namespace

void runBrickWalkBench(const BrickWalkBenchOptions& o) {
  if (o.frames < 2) throw InputError("--frames must be >= 2 for --bricks-vs-incore");
  if (o.rounds < 1) throw InputError("--rounds must be >= 1");
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  std::printf(
      "bricks vs in-core: ray casting %s, TF %s, the renderer's default sampling; per volume "
      "%d rounds alternating a bricked run and an in-core run of %d frames of the same view "
      "(the refined bricked frame; the first frame of each run not counted)\n\n",
      o.size.c_str(), o.tf.c_str(), o.rounds, o.frames);
  std::printf(
      "| volume | type | in-core layout | in-core ms (median) | bricked ms (median) | "
      "bricked / in-core | PSNR bricked vs in-core | bricked levels | bricked textures |\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& spec : o.volumes) {
    std::fprintf(stderr, "bench: %s...\n", spec.c_str());
    const lod::InCoreVolumeSource source(benchVolume(spec));
    DeviceSession device = openDevice("native");
    session::RenderRequest req;
    parseSize(o.size, req.width, req.height);
    req.settings.tf = tf;
    req.repeat = o.frames;
    std::vector<double> bricked, inCore;
    session::RenderResult lastBricks, lastInCore;
    for (int round = 0; round < o.rounds; ++round) {
      req.settings.layout = "bricks";
      lastBricks = session::runRender(device, source, req);
      for (double ms : framesAfterFirst(lastBricks)) bricked.push_back(ms);
      req.settings.layout = "auto";
      lastInCore = session::runRender(device, source, req);
      for (double ms : framesAfterFirst(lastInCore)) inCore.push_back(ms);
    }
    const double b = median(bricked), c = median(inCore);
    std::string levels = "-";
    if (lastBricks.bricks) {
      levels.clear();
      const auto& per = lastBricks.bricks->wantedPerLevel;
      for (std::size_t l = 0; l < per.size(); ++l) {
        if (per[l] == 0) continue;
        levels += (levels.empty() ? "L" : " L") + std::to_string(l) + ":" + std::to_string(per[l]);
      }
    }
    std::printf("| %s | %s | %s | %.1f | %.1f | %.2f | %.2f dB | %s | %s |\n", spec.c_str(),
                std::string(scalarTypeName(source.shape().type())).c_str(),
                lastInCore.layout.c_str(), c, b, b / c, psnr(lastBricks.first, lastInCore.first),
                levels.c_str(), formatBytes(lastBricks.volumeTextureBytes).c_str());
    std::fflush(stdout);
  }
}

}  // namespace tessera::app
