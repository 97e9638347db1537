#pragma once
// Everything one page (or one embedded viewer, frontends/web/tessera.js) holds between
// calls of the C API (frontends/web/src/WebExports*.cpp): the WebGL context, the
// viewer core, the files handed over, the slice views' region, the grid
// view, the zoom swap, an open OME-Zarr store and the crop box's handles.
// One object, made by tessera_init and destroyed by tessera_dispose; the
// exports only marshal arguments to it and its results back.
//
// The member functions below are the session logic (what to show when a
// region is picked, a grid move made, the zoom swaps; which settings are
// valid); they are grouped by feature over WebSession.cpp (the view and
// settings), WebSessionExplore.cpp (slices, region, grid), WebSessionStore.cpp
// (OME-Zarr) and WebSessionZoom.cpp (the zoom swap).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "ZarrStoreView.h"
#include "tessera/core/Camera.h"
#include "tessera/core/SliceImage.h"
#include "tessera/gpu/WebGlContext.h"
#include "tessera/lod/GridNavigator.h"
#include "tessera/session/Exploration.h"
#include "tessera/session/Session.h"
#include "tessera/viewer/CropHandles.h"
#include "tessera/viewer/Explorer.h"
#include "tessera/viewer/Viewer.h"
#include "tessera/viewer/ZoomSwap.h"

namespace tessera::web {

// A file the page handed over (malloc'ed by it, freed here).
struct PickedFile {
  std::string name;
  std::unique_ptr<std::uint8_t, decltype(&std::free)> bytes{nullptr, &std::free};
  std::size_t size = 0;
};

// The last slice per axis (tessera_slice's pixels).
struct SliceViews {
  Image images[3];
};

// Boxes marked in the overview (0: the picked region, red; 1: the grid
// view's last block, cyan), each with the dims of the overview it was given
// for, so that another file never shows a stale box.
struct MarkBox {
  std::optional<lod::VoxelBox> box;
  glm::ivec3 dims{0};
};

struct CropState {
  bool show = false;  // the crop box and its handles in the 3D view
  viewer::CropHandles handles;
};

// A slice of the slice views (tessera_slice): its frame, raster and image.
struct SliceResult {
  SliceFrame frame;
  SliceRaster raster;
  const Image* image = nullptr;
  int count = 0;  // slices along the axis
  bool oriented = false;
  int level = 0;
  bool pending = false;
  std::string note;
};

// How the 3D view projects the overview's voxels (tessera_projection_json).
struct VoxelProjection {
  glm::dmat4 mvp{1.0};
  glm::dvec3 spacing{1.0};
  glm::dvec3 offset{0.0};
};

// The grid view's six moves relative to the view, in the C API's order
// (0 forward, 1 back, 2 left, 3 right, 4 up, 5 down).
inline constexpr lod::ViewMove kViewMoves[6] = {lod::ViewMove::Forward, lod::ViewMove::Back,
                                                lod::ViewMove::Left,    lod::ViewMove::Right,
                                                lod::ViewMove::Up,      lod::ViewMove::Down};

class WebSession {
 public:
  // A WebGL context on the canvas named by `canvasSelector` (WebGL 2 for
  // version 2, else 1) and the viewer on it (profile webgl2 / webgl1).
  WebSession(const std::string& canvasSelector, int webglVersion);
  ~WebSession();
  WebSession(const WebSession&) = delete;
  WebSession& operator=(const WebSession&) = delete;

  // The rendering session on the canvas's context: its view is the 3D view,
  // its exploration what the slice views, region and grid show, its state
  // what tessera_state_json saves and tessera_state_restore restores.
  session::Session& rendering() { return *session_; }
  viewer::Viewer& viewer() { return session_->view(); }
  gpu::GlContext& context() { return context_->gl(); }
  int webglVersion() const { return context_->webglVersion(); }
  bool contextLost() const { return context_->lost(); }
  // After the browser restored a lost WebGL context (a phone sent the page to
  // the background, the GPU reset): the context is made again on the canvas
  // and the session's GPU side on it (Session::loseContext, restoreContext:
  // the same volume, settings, camera, view knobs, exploration, region,
  // overlay and channels, nothing read again). An open OME-Zarr store is
  // made again on it from what the page holds (reopenStore): the page then
  // steps storeOpenStep until it is open and the region or grid block it
  // showed is shown again (Session::showRegionAgain, its chunks fetched
  // when the cache let them go), and the store refines as before.
  void recoverContext();

  // ---- volumes and frames (WebSession.cpp)
  void loadGenerated(const std::string& spec);
  void addFile(PickedFile file) { picked_.push_back(std::move(file)); }
  void clearFiles() { picked_.clear(); }
  // The files handed over, taken (frontends/web/src/WebOverlay.h reads them as an overlay).
  std::vector<PickedFile> takeFiles() { return std::exchange(picked_, {}); }
  // Reads the picked file that names the others; drops them all.
  void loadPickedFiles();
  double renderFrame(int width, int height);  // ms
  void setCamera(double azimuth, double elevation, double zoom);
  // Settings checks: the step range, light, gradient opacity, crop box.
  void setStep(double voxels);
  void setLight(bool headlight, double ambient, double diffuse, double specular, double shininess,
                const glm::dvec3& direction);
  void setGradientOpacity(bool on, double low, double high);
  void setCrop(const glm::dvec3& lo, const glm::dvec3& hi);
  void setFollowingPlane(bool on, double depth);
  void setLabels(bool on, const std::string& table, const std::string& name);
  CropState& crop() { return crop_; }
  // The viewer's extra lines: the region / grid boxes, then the crop box's.
  void refreshExtraLines();
  // Session::restore of a state as JSON text; InputError naming what is
  // wrong (the look stays as it was when the state is refused).
  void restoreState(const std::string& json);
  // The canvas's pixels (RGBA, top row first), valid until the next call.
  const std::uint8_t* readPixels(int width, int height);

  // ---- slice views, region and grid (WebSessionExplore.cpp)
  // The exploration (session/Exploration.h) of what the slices show: the
  // open store's level 0, or the file in the viewer (made for it on first
  // use, sharing its voxels; `cellSide` > 0 asks for cubic grid cells of that
  // side, 0 for the default, -1 keeps the current grid).
  session::Exploration& exploration(int cellSide = -1);
  // True while the viewer shows the region or grid block the exploration
  // put in; a volume loaded since then (another file) ends it.
  bool regionShown();
  const SliceViews& sliceViews() const { return slices_; }
  // The volume the slices show: the overview's, also while a region is shown.
  const Volume& overviewVolume();
  // The voxel space of the slice views, the crosshair, the region and the
  // grid: the overview volume's, or an open store's level 0 (its shape).
  const Volume& sliceShape();
  // The largest cube side (<= 256) whose voxels fit the profile, and why.
  std::pair<int, std::string> defaultRegionSide(const Volume& volume);
  SliceResult slice(int axis, int index, bool colour, double maxPixels);
  double voxelValue(int x, int y, int z);
  // An open store's levels at the time point the session shows (its t
  // axis played), which the slices and the readout read.
  const FetchedZarrSource& storeSliceSource();
  // The name shown for the overview (a store's URL, the file's name).
  std::string overviewName();
  // Shows `box` of the overview at native resolution as the 3D view; back
  // with returnToOverview().
  void showRegion(lod::VoxelBox box);
  void returnToOverview();
  void setMarkBox(int slot, const lod::VoxelBox& box);
  std::optional<VoxelProjection> projection(int width, int height);
  // The grid view (Schultz 2016 §7.3; lod::GridNavigator).
  void gridEnter(int cellSide, const glm::ivec3& voxel);
  // 1 moved, 0 refused at the grid's boundary (the note says why).
  int gridMove(int viewMove);
  void gridStoreFailed();
  void gridStoreShown();
  bool gridShown();
  // A store's grid block asked for and not read yet (the page fetches it).
  bool gridStoreWanted();
  lod::GridNavigator defaultGrid(const Volume& volume);

  // ---- OME-Zarr stores over fetch() (WebSessionStore.cpp)
  ZarrStoreView* store() { return zarr_.get(); }
  ZarrStoreView& theStore();
  // The open store's coarsest level (null when no store is open).
  const Volume* storeOverview();
  void beginStore(const std::string& url);
  // The stored bytes the next store's chunk cache keeps (FetchStorage's
  // budget, least recently used first out): kStoreFetchedBytes unless the
  // page asks for less (?zarrcache=MiB). InputError outside
  // kStoreCacheMinBytes..kStoreFetchedBytes.
  void setStoreCacheBytes(double bytes);
  // The share of the frame budget a store's strips take (StorePace::
  // stripShare), from the next frame on: the page's ?stripshare=, for
  // comparisons. InputError outside kStoreStripShareMin..1.
  void setStoreStripShare(double share);
  // The store of a lost context on the restored one: its chunks, metadata
  // and levels kept, its GPU side (atlas, page table, ray caster) made again
  // by storeOpenStep, which then keeps the restored camera and TF.
  void reopenStore(ZarrStoreView::Host host);
  bool storeOpenStep();
  void closeStore();
  // The store's region or grid block is the 3D view (not the store's frames).
  bool storeRegionShown() { return storeOverview() && regionShown(); }
  // The store's level-0 box of these ranges (clamped; errors name the store).
  lod::VoxelBox storeRegionBox(const lod::VoxelBox& asked);
  bool storeRegionPrefetch(const lod::VoxelBox& asked);
  void showStoreRegion(const lod::VoxelBox& asked);
  void storeRegionOverview();
  // The store's frame with the region and grid block marked, paced as the
  // viewer's progressive frames (its frameBudgetMs); `viewChanged`: a
  // preview at once, else the canvas keeps its image until the frame is done;
  // `inputWaitedMs`: StorePace::inputWaitedMs.
  StoreFrame storeFrame(int width, int height, bool viewChanged, double inputWaitedMs = -1.0);
  // Whether the time point shown is on the canvas whole, as playback's
  // next one waits for (Session::stepPlayback): the store's, when its t
  // axis plays over bricks; true otherwise.
  bool storeTimeFinished();
  // About a budget of the pending store frame (ZarrStoreView::refine).
  StoreFrame storeRefine() { return theStore().refine(); }
  // The grid view's last block over a store, while the store is drawn.
  std::optional<lod::VoxelBox> storeGridBlock();

  // ---- the zoom-driven level swap (WebSessionZoom.cpp): the exploration's
  // (session::Exploration::keepZoom), over the loaded file.
  bool zoomActive();
  const viewer::ZoomSwap* zoomSwap() { return zoomActive() ? explore()->zoom() : nullptr; }
  // The whole loaded volume while the swap drives the view (null otherwise).
  const Volume* zoomOverview();
  const std::string& zoomName() { return explore()->label(); }
  int zoomMediumLevel() const { return zoomMediumLevel_; }
  std::optional<lod::VoxelBox> zoomBox();
  void zoomStart(int viewPixels, double overviewVoxels, double blockVoxels);
  void zoomForget() {
    if (explore()) explore()->endZoom();
    zoomLastFrameMs_ = -1.0;
  }
  // Hands the view back to the whole volume, the camera kept.
  void zoomStop();
  double zoomFrame(int width, int height);

 private:
  void applyMarkBoxes();
  std::string overviewKey(const Volume& v);
  // The session on the context, with the page's sampling and its view made.
  void makeSession();
  void showGridBlock(const session::ExploreStep& step);
  // The session's exploration, or null before one was made.
  session::Exploration* explore() {
    return session_->exploring() ? &session_->exploration() : nullptr;
  }

  // Declared in destruction order's reverse: the viewer's GPU objects go
  // before the context.
  std::string canvasSelector_;
  std::unique_ptr<gpu::WebGlContext> context_;  // made again by recoverContext
  std::unique_ptr<ZarrStoreView> zarr_;
  std::unique_ptr<session::Session> session_;
  std::vector<PickedFile> picked_;
  SliceViews slices_;
  MarkBox marks_[2];
  std::string exploreKey_;      // the overview it was made for: name and dims
  int askedCell_ = 0;           // the grid cell side asked for (0: the default)
  bool storeReopened_ = false;  // the store being opened again keeps the view's camera
  std::uint64_t storeCacheBytes_ = kStoreFetchedBytes;
  double storeStripShare_ = StorePace{}.stripShare;
  int zoomMediumLevel_ = 0;
  double zoomLastFrameMs_ = -1.0;
  CropState crop_;
  std::vector<std::uint8_t> pixels_;
};

// The session tessera_init made (GpuError when there is none yet).
WebSession& session();
// Null before tessera_init and after tessera_dispose.
WebSession* sessionIfAny();
void startSession(const std::string& canvasSelector, int webglVersion);
void endSession();

}  // namespace tessera::web
