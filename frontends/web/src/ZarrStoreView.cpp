#include "ZarrStoreView.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "tessera/core/Timing.h"
#include "tessera/gpu/Draw.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/render/Overlay.h"
#include "tessera/session/BrickRefinement.h"

namespace tessera::web {

namespace {

// Decoded chunks' stored bytes the page keeps: compressed, so many chunks
// (a brick read with its apron touches its neighbours' chunks).
constexpr std::uint64_t kFetchedBytes = 48ull << 20;
// As the viewer core plans its uploads (viewer/Viewer.cpp).
constexpr int kPlanImageSize = 1024;
constexpr int kSkipBlock = 8;
// Streaming (reading and uploading arrived bricks) before a frame is drawn.
constexpr double kStreamMs = 150.0;

}  // namespace

FetchedZarrSource::FetchedZarrSource(std::shared_ptr<const ZarrStore> store,
                                     std::shared_ptr<const FetchStorage> storage)
    : zarr_(store), store_(std::move(store)), storage_(std::move(storage)) {}

bool FetchedZarrSource::prefetch(int level, const lod::VoxelBox& box) const {
  bool ready = true;
  for (const std::string& key : store_->chunkKeys(level, box.begin, box.end)) {
    ready = storage_->ready(key) && ready;  // lists every key the box lacks
  }
  return ready;
}

bool FetchedZarrSource::resident(int level, const lod::VoxelBox& box) const {
  for (const std::string& key : store_->chunkKeys(level, box.begin, box.end)) {
    if (!storage_->holds(key)) return false;
  }
  return true;
}

ZarrStoreView::ZarrStoreView(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                             const std::string& url)
    : context_(context),
      limits_(limits),
      storage_(std::make_shared<FetchStorage>(url, kFetchedBytes)) {}

bool ZarrStoreView::open() {
  if (isOpen()) return true;
  // Each step throws while a key it reads has not arrived; then the keys
  // it wanted are fetched and the step runs again.
  try {
    if (!store_) store_ = std::make_shared<const ZarrStore>(storage_);
    if (!source_) source_ = std::make_shared<const FetchedZarrSource>(store_, storage_);
    const int top = store_->levelCount() - 1;
    const lod::VoxelBox all{glm::ivec3(0), store_->level(top).dims};
    if (!source_->prefetch(top, all)) return false;
    coarsest_ = source_->readBox(top, all);
    const lod::MultiresVolumeSource volumeSource(source_);
    active_ = render::createTechnique(
        "raycast", context_, limits_, volumeSource,
        {.imageSize = {kPlanImageSize, kPlanImageSize}, .skipBlock = kSkipBlock}, "bricks");
  } catch (const std::exception&) {
    if (storage_->hasWanted()) return false;
    throw;
  }
  bricks_ = active_.upload.layout ? active_.upload.layout->streaming() : nullptr;
  if (!bricks_) throw Error(storage_->describe() + ": the bricks layout was not created");
  compositor_ = std::make_unique<render::HybridCompositor>(context_);
  return true;
}

StoreFrame ZarrStoreView::frame(const Camera& viewerCamera, const RenderSettings& settings,
                                const TransferFunction& tf, std::uint64_t tfRevision, bool box,
                                bool axes, int width, int height, int maxVolumePixels,
                                const std::vector<render::OverlayLine>& marks) {
  const auto t0 = std::chrono::steady_clock::now();
  StoreFrame f;
  if (tfRevision != tfRevision_) {
    active_.technique->setTransferFunction(tf);
    tfRevision_ = tfRevision;
  }
  // The viewer's orbit, zoom and pan, framed on this volume.
  Camera camera = viewerCamera;
  const Volume& shape = store_->shape();
  camera.frame(shape);
  double scale = 1.0;
  const double pixels = static_cast<double>(width) * height;
  if (maxVolumePixels > 0 && pixels > maxVolumePixels) scale = std::sqrt(maxVolumePixels / pixels);
  f.renderWidth = std::max(1, static_cast<int>(std::lround(width * scale)));
  f.renderHeight = std::max(1, static_cast<int>(std::lround(height * scale)));
  gpu::clearErrors();
  // A ray march costs far more than an update (SwiftShader: most of a
  // second), so stream for up to kStreamMs before drawing, and a frame
  // shows everything that has arrived; the page fetches between frames.
  f.bricks = session::BrickRefinement(*bricks_).step(camera, f.renderWidth, f.renderHeight, tf,
                                                     {.streamMs = kStreamMs, .idleWaitMs = 0.0});
  // Over transparent black; the compositor adds the background and lines.
  RenderSettings pass = settings;
  pass.background = glm::dvec4(0.0);
  const gpu::Texture& image =
      active_.technique->render(camera, pass, f.renderWidth, f.renderHeight, 0.0);
  render::OverlayOptions overlays;
  overlays.box = box;
  overlays.axes = axes;
  std::vector<render::OverlayLine> lines = render::overlayLines(shape, overlays);
  lines.insert(lines.end(), marks.begin(), marks.end());
  compositor_->setOverlayLines(std::move(lines));
  compositor_->composeInto(image, camera, glm::vec4(settings.background), shape.extent(), 0,
                           glm::ivec4(0, 0, width, height));
  std::uint8_t pixel[4];
  gpu::readPixelsRgba8({0, 0, 1, 1}, pixel);  // waits for the frame (glFinish does not)
  gpu::checkErrors("OME-Zarr frame");
  f.ms = msSince(t0);
  return f;
}

}  // namespace tessera::web
