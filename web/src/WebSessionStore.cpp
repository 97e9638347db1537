// The session's OME-Zarr store over fetch() (web/zarr-url.js drives it): the
// page fetches the keys a step wants and hands them over; the store renders
// through the bricks layout coarse to fine (ZarrStoreView.h) with the viewer
// core's camera, transfer function and settings. Its bread-slice region is
// read with bounded reads: only the level-0 chunks overlapping the box are
// fetched (asynchronously, by the page), then one readBox, never the level
// whole.
#include <algorithm>

#include "WebSession.h"
#include "tessera/core/Error.h"
#include "tessera/core/Histogram.h"

namespace tessera::web {

ZarrStoreView& WebSession::theStore() {
  if (!zarr_) throw Error("no OME-Zarr store is open");
  return *zarr_;
}

const Volume* WebSession::storeOverview() {
  return zarr_ && zarr_->isOpen() ? &zarr_->coarsest() : nullptr;
}

void WebSession::beginStore(const std::string& url) {
  zoomStop();
  zarr_ = std::make_unique<ZarrStoreView>(context(), viewer().limits(), url);
}

// True once open (the coarsest level is on the GPU): its histogram goes to
// the TF editor and the camera frames it.
bool WebSession::storeOpenStep() {
  ZarrStoreView& z = theStore();
  if (!z.open()) return false;
  viewer::Viewer& v = viewer();
  v.tfEditor().setHistogram(Histogram::compute(z.coarsest(), 256, z.store().shape().window()));
  v.resetCamera();
  return true;
}

// The viewer core's volume shows again.
void WebSession::closeStore() {
  zarr_.reset();
  storeRegion_ = {};
}

// Ends past the level are clamped; an empty box or one that starts outside
// is an error naming the store.
lod::VoxelBox WebSession::storeRegionBox(const lod::VoxelBox& asked) {
  ZarrStoreView& z = theStore();
  const glm::ivec3 d = z.source().levelInfo(0).dims;
  lod::VoxelBox box = asked;
  const char* names = "xyz";
  for (int a = 0; a < 3; ++a) {
    if (box.begin[a] < 0 || box.begin[a] >= d[a] || box.end[a] <= box.begin[a]) {
      throw InputError(z.storage().describe() + ": region: " + names[a] + " range " +
                       std::to_string(box.begin[a]) + ":" + std::to_string(box.end[a]) +
                       " is empty or starts outside 0:" + std::to_string(d[a]) + " of level 0");
    }
    box.end[a] = std::min(box.end[a], d[a]);
  }
  return box;
}

bool WebSession::storeRegionPrefetch(const lod::VoxelBox& asked) {
  ZarrStoreView& z = theStore();
  if (!z.isOpen()) throw Error(z.storage().describe() + ": the store is not open yet");
  return z.source().prefetch(0, storeRegionBox(asked));
}

// Reads the box (its chunks fetched: storeRegionPrefetch) at level 0 and
// makes it the viewer's volume, placed and windowed as in the store (what
// `tessera render STORE --region` reads); the page then draws the viewer
// instead of the store until it goes back to the store's overview.
void WebSession::showStoreRegion(const lod::VoxelBox& asked) {
  ZarrStoreView& z = theStore();
  const lod::VoxelBox box = storeRegionBox(asked);
  if (!z.source().prefetch(0, box)) {
    throw Error(z.storage().describe() + ": region: its chunks have not all arrived");
  }
  Volume region = z.source().readBox(0, box);
  region.setWindow(z.store().shape().window());
  const ValueRange window = region.window();
  viewer::Viewer& v = viewer();
  const Camera camera = v.camera();
  const auto text = [&](int a) {
    return std::to_string(box.begin[a]) + ":" + std::to_string(box.end[a]);
  };
  StoreRegion& r = storeRegion_;
  // From the store view (not from another region of it): its camera.
  if (!r.shown) r.overviewCamera = camera;
  r.box = box;
  r.shown = true;
  r.gridBlock = false;  // gridStoreShown says when it is the grid's
  v.setVolume(std::move(region),
              z.storage().describe() + " region " + text(0) + "," + text(1) + "," + text(2));
  v.setWindow(window);
  // Framed on the region (setVolume), seen from the store view's
  // direction, projection and zoom.
  Camera& c = v.camera();
  c.projection = camera.projection;
  c.azimuthDeg = camera.azimuthDeg;
  c.elevationDeg = camera.elevationDeg;
  c.zoom = camera.zoom;
}

// Back to the store's overview from its region (the region stays known,
// for its outline in the slice views).
void WebSession::storeRegionOverview() {
  if (storeRegion_.shown) viewer().camera() = storeRegion_.overviewCamera;
  storeRegion_.shown = false;
}

std::optional<lod::VoxelBox> WebSession::storeGridBlock() {
  if (!grid_.block || grid_.storeWanted || !storeOverview() || storeRegion_.shown) {
    return std::nullopt;
  }
  return grid_.block;
}

StoreFrame WebSession::storeFrame(int width, int height) {
  viewer::Viewer& v = viewer();
  ZarrStoreView& z = theStore();
  // The picked region as a red box over the store, as over a file's
  // overview (applyMarkBoxes), composed by depth.
  std::vector<render::OverlayLine> marks;
  const StoreRegion& r = storeRegion_;
  const Volume& shape = z.store().shape();
  if (!r.gridBlock && glm::all(glm::lessThan(r.box.begin, r.box.end))) {
    marks = viewer::boxLines(r.box, shape.dims(), shape.extent(), {1.0f, 0.25f, 0.2f, 1.0f});
  }
  // The grid view's last block, cyan (level-0 voxels, as the region).
  if (const std::optional<lod::VoxelBox> block = storeGridBlock()) {
    const auto cyan =
        viewer::boxLines(*block, shape.dims(), shape.extent(), {0.25f, 0.85f, 0.95f, 1.0f});
    marks.insert(marks.end(), cyan.begin(), cyan.end());
  }
  return z.frame(v.camera(), v.frameSettings(), v.tfEditor().transferFunction(),
                 v.tfEditor().revision(), v.showBoundingBox, v.showAxes, width, height,
                 v.maxVolumePixels, marks);
}

}  // namespace tessera::web
