#include "bench/BenchScale.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>

#include "bench/BenchBricks.h"
#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/Timing.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

// "64^3" from the plan's reason ("... as 64^3 bricks (+1 voxel apron) ...").
std::string brickText(const std::string& reason) {
  const std::size_t end = reason.find("^3 bricks");
  if (end == std::string::npos) return "?";
  const std::size_t begin = reason.rfind(' ', end);
  return reason.substr(begin + 1, end - begin - 1) + "^3";
}

RenderRequest requestFor(const ScaleBenchOptions& o, int side) {
  RenderRequest req;
  parseSize(o.size, req.width, req.height);
  req.settings.render = RenderSettings();  // plain sampling, as the bricks bench
  req.settings.render.stepVoxels = scaleStepVoxels(side, std::max(req.width, req.height));
  req.settings.skipBlock = scaleSkipBlock(side);
  req.settings.tf = TransferFunction::fromPresetOrFile(o.tf);
  req.settings.layout = "bricks";
  req.repeat = 1;
  return req;
}

// One row, in this (child) process.
void runRow(const ScaleBenchOptions& o, int side, const std::string& profile) {
  const std::string spec = "head16:" + std::to_string(side);
  const double virtualBytes = 2.0 * side * double(side) * side;
  char head[160];
  std::snprintf(head, sizeof head, "| %d³ (%s) | %s |", side,
                formatBytes(static_cast<std::uint64_t>(virtualBytes)).c_str(), profile.c_str());
  try {
    gpu::DeviceSession device = openDevice(profile);
    const lod::MultiresVolumeSource source(std::make_shared<lod::ProceduralMultiresSource>(spec));
    const RenderRequest req = requestFor(o, side);
    const auto t0 = std::chrono::steady_clock::now();
    const RenderResult r = runRender(device, source, req);
    const double wallMs = msSince(t0);
    const BricksRun& b = *r.bricks;
    // From opening (atlas, page table, the coarsest level, the shader) to
    // the first and to the refined image: the run less the frame drawn
    // again after refining (and its read-back).
    const double refinedMs = wallMs - r.frameMs.front();
    const double firstMs = refinedMs - (b.completeMs - b.firstFrameMs);
    std::printf(
        "%s %s | %.2f / %d | %.0f | %.0f%s | %d | %s | %llu (%s) | %s / %s | %s / %s |\n", head,
        brickText(r.layoutReason).c_str(), req.settings.render.stepVoxels, req.settings.skipBlock,
        firstMs, refinedMs, b.complete ? "" : " (limit)", b.refineFrames,
        levelsText(b.wantedPerLevel).c_str(), static_cast<unsigned long long>(b.bricksRead),
        formatBytes(b.bytesRead).c_str(), formatBytes(device.context->ledger().peakBytes()).c_str(),
        formatBytes(device.limits.textureBudget).c_str(), formatBytes(peakRssBytes()).c_str(),
        formatBytes(HostBudget::global().limitBytes()).c_str());
  } catch (const Error& e) {
    std::printf("%s refused: %s | | | | | | | | |\n", head, e.what());
  }
  std::fflush(stdout);
}

}  // namespace

double scaleStepVoxels(int side, int pixels) {
  return std::min(8.0, 0.5 * std::max(1.0, static_cast<double>(side) / std::max(1, pixels)));
}

int scaleSkipBlock(int side) {
  return std::max(8, side / 128);
}

void runScaleBench(const ScaleBenchOptions& o) {
  std::printf(
      "scale: head16:N (u16, generated brick by brick) through bricks, ray casting %s, TF %s, "
      "refined to completion; one child process per row (its own RSS peak)\n\n",
      o.size.c_str(), o.tf.c_str());
  std::printf(
      "| volume (virtual bytes) | profile | brick | step vox / skip block | first image ms | "
      "refined ms | refine frames | levels (refined) | bricks generated (bytes) | texture peak "
      "/ budget | host RSS peak / budget |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  for (int side : o.sides) {
    for (const std::string& profile : o.profiles) {
      std::fprintf(stderr, "bench: head16:%d on %s...\n", side, profile.c_str());
      const pid_t child = fork();
      if (child < 0) throw Error("bench --scale: fork failed");
      if (child == 0) {
        runRow(o, side, profile);
        _exit(0);
      }
      int status = 0;
      waitpid(child, &status, 0);
      if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::printf("| %d³ | %s | the run died (status %d) | | | | | | | | |\n", side,
                    profile.c_str(), status);
        std::fflush(stdout);
      }
    }
  }
}

}  // namespace tessera::app
