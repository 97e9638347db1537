#include "tessera/session/BrickRefinement.h"

#include <chrono>

#include "tessera/core/Timing.h"

namespace tessera::session {

layout::BricksFrame BrickRefinement::step(const Camera& camera, int width, int height,
                                          const TransferFunction& tf, const StreamPace& pace) {
  const auto t0 = std::chrono::steady_clock::now();
  if (idle_ && pace.idleWaitMs > 0.0) layout_.waitForBricks(pace.idleWaitMs);
  layout::BricksFrame f = layout_.update(camera, width, height, tf);
  int uploaded = f.uploaded;
  // A ray march costs far more than an update (SwiftShader: most of a
  // second), so a paced step streams on and a frame shows all that arrived.
  while (!f.complete && msSince(t0) < pace.streamMs) {
    const std::uint64_t read = layout_.streamerStats().bricksRead;
    f = layout_.update(camera, width, height, tf);
    uploaded += f.uploaded;
    if (f.uploaded > 0) continue;
    if (pace.idleWaitMs > 0.0) {
      layout_.waitForBricks(pace.idleWaitMs);
    } else if (layout_.streamerStats().bricksRead == read) {
      break;
    }
  }
  idle_ = f.uploaded == 0;
  f.uploaded = uploaded;
  return f;
}

RefineRun BrickRefinement::refine(const Camera& camera, int width, int height,
                                  const TransferFunction& tf, const std::function<void()>& draw,
                                  const RefineLimits& limits,
                                  const std::function<void(const RefineRun&, double)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  RefineRun run;
  double lastReportMs = 0.0;
  idle_ = false;
  // This run must end: a brick that keeps failing is given up, not read
  // again every back-off while the rest waits.
  layout_.retryFailingReads(false);
  while (true) {
    run.last = step(camera, width, height, tf, {.streamMs = 0.0, .idleWaitMs = 50.0});
    draw();
    if (++run.frames == 1) run.firstFrameMs = msSince(t0);
    if (run.last.complete || run.frames >= limits.maxFrames ||
        msSince(t0) > 1000.0 * limits.maxSeconds) {
      break;
    }
    if (progress && msSince(t0) - lastReportMs > 1000.0) {  // once a second
      lastReportMs = msSince(t0);
      progress(run, lastReportMs);
    }
  }
  run.completeMs = msSince(t0);
  const lod::StreamerStats stats = layout_.streamerStats();
  run.failedReads = stats.failingErrors;
  run.failedReadCount = stats.failingErrorCount;
  return run;
}

}  // namespace tessera::session
