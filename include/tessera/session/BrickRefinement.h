#pragma once
// Progressive refinement of a streamed volume (layout/StreamingLayout.h),
// the one loop every front end drives: each step selects the bricks the view
// wants, requests the missing ones and uploads what has arrived; the front
// end draws between steps, so a view first shows coarse levels and sharpens
// as bricks arrive (Schultz 2016 §7.3). The CLI refines frame 0 to the end
// before writing it; the web page streams for a slice of each animation
// frame while its fetches arrive.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tessera/core/Camera.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/layout/StreamingLayout.h"

namespace tessera::session {

// How long one step may stream before the front end draws.
struct StreamPace {
  // Keep updating (reading and uploading arrived bricks) for up to this long
  // while the view is not complete; 0: one update per step.
  double streamMs = 0.0;
  // When an update uploads nothing, wait up to this long for a read to
  // finish (the reader threads of a local store); 0: do not wait, and end
  // the step once an update neither uploads nor reads (the page's fetches
  // arrive between animation frames).
  double idleWaitMs = 0.0;
};

// Where refining a view to completion stops. A brick whose reads keep
// failing does not hold it up: it is given up after the streamer's failure
// policy (lod::BrickStreamerOptions: attemptsBeforeFailing reads and the
// back-off between them) and shows its coarser level, so a dead chunk ends
// the run in seconds; these limits are for a source that is merely slow.
struct RefineLimits {
  int maxFrames = 10000;
  double maxSeconds = 600.0;
};

// What refining a view to completion took.
struct RefineRun {
  int frames = 0;             // frames drawn until complete (the first image is frame 1)
  double firstFrameMs = 0.0;  // to the first image (coarsest level)
  double completeMs = 0.0;    // to the refined image
  layout::BricksFrame last;   // the last step's state (complete, failing, per level)
  // The distinct errors of the bricks given up (each names the chunk, file
  // or URL that failed), sorted, at most lod::StreamerStats::kListedErrors
  // of failedReadCount.
  std::vector<std::string> failedReads;
  std::size_t failedReadCount = 0;
};

class BrickRefinement {
 public:
  explicit BrickRefinement(layout::StreamingLayout& layout) : layout_(layout) {}

  // One step for the view (camera framed on the source's shape): updates as
  // `pace` allows; `uploaded` counts every upload of the step.
  layout::BricksFrame step(const Camera& camera, int width, int height, const TransferFunction& tf,
                           const StreamPace& pace);

  // Steps and draws (`draw` after every step) until every brick the view
  // wants is resident or given up, or a limit is reached; `progress` (may
  // be empty) is told about once a second while it takes long. Bricks given
  // up stay given up for the layout's life (StreamingLayout::
  // retryFailingReads(false)); the viewers, which only step(), keep
  // retrying theirs.
  RefineRun refine(const Camera& camera, int width, int height, const TransferFunction& tf,
                   const std::function<void()>& draw, const RefineLimits& limits,
                   const std::function<void(const RefineRun&, double ms)>& progress = {});

  layout::StreamingLayout& layout() { return layout_; }

 private:
  layout::StreamingLayout& layout_;
  bool idle_ = false;  // the last update uploaded nothing
};

}  // namespace tessera::session
