#include "bench/BenchBricks.h"

#include <sys/resource.h>

#include <cstdio>
#include <memory>

#include "cli/Commands.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/layout/Planner.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

RenderRequest requestFor(const BricksBenchOptions& o, const TransferFunction& tf,
                         const std::string& layout) {
  RenderRequest req;
  parseSize(o.size, req.width, req.height);
  req.settings.render = RenderSettings();  // plain sampling, as the runs were measured
  req.settings.tf = tf;
  req.settings.layout = layout;
  req.repeat = o.frames + 1;
  req.rotateDeg = o.rotate;
  return req;
}

}  // namespace

std::uint64_t peakRssBytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::uint64_t>(u.ru_maxrss) * 1024;  // Linux: KiB
}

std::string levelsText(const std::vector<int>& perLevel) {
  std::string s;
  for (std::size_t l = 0; l < perLevel.size(); ++l) {
    if (perLevel[l] == 0) continue;
    char item[40];
    std::snprintf(item, sizeof item, "%sL%zu:%d", s.empty() ? "" : " ", l, perLevel[l]);
    s += item;
  }
  return s;
}

void runBricksBench(const BricksBenchOptions& o) {
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  std::printf(
      "bricks: ray casting %s, TF %s, refined first frame then %d frames rotating %g "
      "deg (each streams within the per-frame upload budget)\n\n",
      o.size.c_str(), o.tf.c_str(), o.frames, o.rotate);
  std::printf(
      "| volume | profile | layout | first image ms | refined ms | rotating ms (median) | "
      "in-core ms | bricked / in-core | levels (refined) | textures / budget | bricks "
      "read | peak RSS so far |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const std::string& spec : o.volumes) {
    for (const std::string& profile : o.profiles) {
      std::fprintf(stderr, "bench: %s on %s...\n", spec.c_str(), profile.c_str());
      DeviceSession device = openDevice(profile);
      const lod::MultiresVolumeSource source(std::make_shared<lod::ProceduralMultiresSource>(spec));
      const RenderResult r = runRender(device, source, requestFor(o, tf, "bricks"));
      std::vector<double> rotating(r.frameMs.begin() + 1, r.frameMs.end());
      const double rotatingMs = median(rotating);
      // The baseline: the same volume in core, where the profile holds it.
      std::string inCore = "-", ratio = "-";
      if (o.baseline && r.bricks) {
        layout::PlanRequest pr;
        pr.streamed = false;
        const layout::Plan p = layout::planLayout(source.shape(), device.limits, pr);
        const std::uint64_t voxels = source.shape().voxelCount();
        if (!p.downsampled() && voxels <= HostBudget::global().limitBytes()) {
          const RenderResult b = runRender(device, source, requestFor(o, tf, p.layout.layout));
          const double baseMs = median(std::vector<double>(b.frameMs.begin() + 1, b.frameMs.end()));
          char text[32];
          std::snprintf(text, sizeof text, "%.0f (%s)", baseMs, b.layout.c_str());
          inCore = text;
          std::snprintf(text, sizeof text, "%.2f", rotatingMs / baseMs);
          ratio = text;
        }
      }
      const std::string lv = r.bricks ? levelsText(r.bricks->wantedPerLevel) : "L0 (in core)";
      std::printf(
          "| %s | %s | %s | %.0f | %.0f | %.0f | %s | %s | %s | %s / %s | %llu (%s) | %s |\n",
          spec.c_str(), profile.c_str(), r.layout.c_str(),
          r.bricks ? r.bricks->firstFrameMs : r.frameMs.front(),
          r.bricks ? r.bricks->completeMs : r.frameMs.front(), rotatingMs, inCore.c_str(),
          ratio.c_str(), lv.c_str(), formatBytes(r.textureBytes).c_str(),
          formatBytes(device.limits.textureBudget).c_str(),
          static_cast<unsigned long long>(r.bricks ? r.bricks->bricksRead : 0),
          formatBytes(r.bricks ? r.bricks->bytesRead : 0).c_str(),
          formatBytes(peakRssBytes()).c_str());
      std::fflush(stdout);
    }
  }
}

}  // namespace tessera::app
