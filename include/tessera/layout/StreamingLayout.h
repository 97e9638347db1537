#pragma once
// What a front end drives of a layout that streams its volume (bricks of a
// multiresolution source, layout/BricksLayout.h) instead of holding it: each
// frame it selects what the view wants, requests and uploads it, and says how
// far the refinement has come. A caller asks Layout::streaming() for it
// rather than knowing the layout's class or name.
#include <cstdint>
#include <memory>
#include <vector>

#include "tessera/core/Camera.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/layout/Layout.h"
#include "tessera/lod/BrickGrid.h"
#include "tessera/lod/BrickStreamer.h"

namespace tessera::layout {

// What one update() did and what the page table now holds.
struct BricksFrame {
  bool complete = false;         // every brick the view wants is resident or failing (left coarser)
  int wanted = 0;                // bricks in the view's cut
  int uploaded = 0;              // bricks uploaded this frame
  int missing = 0;               // wanted, not resident
  int failing = 0;               // missing because their reads keep failing
  bool limitedByBudget = false;  // some brick stayed coarser because the atlas is full
  std::vector<int> wantedPerLevel;  // the cut, bricks per level
  std::vector<int> cellsPerLevel;   // page-table cells drawn from each level (last: transparent)
};

// What one update() may do besides selecting levels and requesting bricks.
struct UpdatePace {
  double uploadMs = 40.0;                   // stop uploading after about this long
  std::uint64_t uploadBytes = 16ull << 20;  // or this many bytes (0: upload nothing)
  int inlineReads = 8;  // without reader threads: bricks read (0: none, they wait)
};

class StreamingLayout {
 public:
  virtual ~StreamingLayout() = default;
  // One frame's level selection, requests, uploads and page table. The
  // camera must be framed on the source's shape (Camera::frame).
  virtual BricksFrame update(const Camera& camera, int width, int height,
                             const TransferFunction& tf) = 0;
  // Waits (up to ms) for a read to finish: the render loop's idle.
  virtual void waitForBricks(double ms) = 0;
  virtual lod::StreamerStats streamerStats() const = 0;
  // Whether bricks whose reads keep failing are read again after their
  // back-off (lod::BrickStreamer::retryFailing): yes while a viewer shows
  // the volume; a run that refines to completion gives them up.
  virtual void retryFailingReads(bool retry) = 0;
  // How much one update() does besides selecting and requesting: a front
  // end that draws within a frame budget between updates keeps each to a
  // part of it.
  virtual void setUpdatePace(const UpdatePace& pace) = 0;
  virtual int slotCount() const = 0;               // atlas slots
  virtual const lod::BrickGrid& grid() const = 0;  // the bricks and levels it streams
  virtual const LayoutPlan& plan() const = 0;      // what it allocated (Layout::plan)
  // Per level-0 brick cell of grid() (x fastest), the level the page table
  // shows there now, or -1 where it shows a transparent cell's constant:
  // the levels a frame drawn now samples, which its reference reads.
  virtual std::vector<int> cellLevels() const = 0;
  // Streams other pyramids of the same grid (another time point of a
  // store: one per channel the layout was made with) into the same
  // textures: every brick of the old ones is let go, the new coarsest
  // level read and pinned in the same slots, and the finer bricks streamed
  // by the next update()s as at the start; nothing is allocated on the GPU.
  // false, with nothing changed, when a pyramid's levels, brick grid or
  // stored precision differ (the caller makes a layout for them instead).
  // Throws what reading the coarsest level throws.
  virtual bool replaceSources(std::vector<std::shared_ptr<const lod::MultiresSource>> sources) = 0;
};

}  // namespace tessera::layout
