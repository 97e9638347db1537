// StreamedFrames: the interactive front ends' frames of a streamed volume
// (session/StreamedFrames.h), the frames Session::run draws for the same
// settings (createTechnique with layout bricks, prepareFrame, the one
// refinement loop), kept on the GPU between front-end frames and refined a
// step at a time instead of to the end in one call.
#include "tessera/session/StreamedFrames.h"

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/layout/ChannelLayouts.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/lod/WindowedSource.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/ChannelTechnique.h"
#include "tessera/session/RenderRun.h"
#include "tessera/session/Session.h"

namespace tessera::session {

// Declared in the order they may go: the refinement steps the technique's
// layout, which reads the source (and, drawing channels, the set).
struct StreamedFrames::Gpu {
  std::shared_ptr<const lod::MultiresSource> pyramid;  // the session's, the layout's made over
  std::unique_ptr<lod::MultiresVolumeSource> source;   // it through the window shown
  // Channels (ChannelView::overBricks): the set the layout reads at every
  // update and bind (the channel view's, copied in before each frame), the
  // layout over the channels' pyramids and the technique drawing them.
  std::unique_ptr<ChannelSet> channels;
  std::unique_ptr<layout::Layout> channelLayout;
  render::TechniqueOnVolume technique;
  std::unique_ptr<render::Technique> channelTechnique;
  std::unique_ptr<BrickRefinement> refinement;
  std::string key;       // what the technique was made for
  std::string frameKey;  // what the last frame drew
  const gpu::Texture* frame = nullptr;
  render::Technique& drawn() { return channels ? *channelTechnique : *technique.technique; }
};

namespace {

// What makes the layout and technique again: the technique and its options,
// the size and the window the bricks are classified through (or the
// channels drawn).
std::string techniqueKey(const Settings& s, int width, int height, ValueRange window,
                         int channels) {
  nlohmann::json key = {s.technique, s.lutSize, s.slices,   s.classify, s.gradient,
                        width,       height,    window.min, window.max, channels};
  return key.dump();
}

}  // namespace

StreamedFrames::StreamedFrames(Session& session) : session_(session) {}
StreamedFrames::~StreamedFrames() = default;

// The last layout's textures go first: one atlas on the GPU at a time.
void StreamedFrames::makeLayout(const std::shared_ptr<const lod::MultiresSource>& pyramid,
                                const Settings& s, int width, int height, ValueRange window,
                                const std::string& key) {
  gpu::DeviceSession& device = session_.device();
  gpu_.reset();
  complete_ = false;
  auto next = std::make_unique<Gpu>();
  next->pyramid = pyramid;
  layout::StreamingLayout* bricks = nullptr;
  if (drawsChannels()) {
    // As Session::renderChannels draws a store's channels over bricks.
    next->channels = std::make_unique<ChannelSet>(session_.channelView().channels());
    const StreamedSeries::Pyramids sources = session_.streamedChannels();
    next->channelLayout = layout::createChannelLayout(
        "bricks", *next->channels, [&] { return sources; }, device.limits,
        device.context->ledger());
    const render::TechniqueEntry& entry = channelTechnique(s.technique);
    requireChannelBricks(entry, next->channelLayout->plan().reason);
    render::TechniqueOptions options = s.techniqueOptions({width, height});
    options.skipBlock = 0;  // the block grid is one volume's
    next->channelTechnique = render::TechniqueRegistry::global().create(
        entry.name, {*device.context, device.limits, next->channels->geometry(),
                     next->channelLayout.get(), options});
    bricks = next->channelLayout->streaming();
  } else {
    next->source = std::make_unique<lod::MultiresVolumeSource>(
        std::make_shared<lod::WindowedSource>(pyramid, window));
    next->technique =
        render::createTechnique(s.technique, *device.context, device.limits, *next->source,
                                s.techniqueOptions({width, height}), "bricks");
    bricks = next->technique.upload.layout ? next->technique.upload.layout->streaming() : nullptr;
    if (!bricks) {
      throw InputError("technique " + s.technique + " keeps its own storage (" +
                       next->technique.storageName() +
                       "), which does not stream bricks: a series over bricks is drawn by one "
                       "that samples a layout (raycast, slice3d)");
    }
  }
  // A viewer keeps asking for a brick whose reads failed, after its back-off.
  bricks->retryFailingReads(true);
  next->refinement = std::make_unique<BrickRefinement>(*bricks);
  next->key = key;
  gpu_ = std::move(next);
  timePoint_ = session_.timePoint();
  ++layoutsMade_;
}

bool StreamedFrames::drawsChannels() const {
  return session_.hasChannelView() && session_.channelView().overBricks() &&
         session_.streamedChannels().size() > 1;
}

// Another time point of the same store: its bricks streamed into the
// atlas, page table and technique already on the GPU (no texture made, no
// shader compiled); a pyramid of another grid keeps gpu_ as it was, and
// render() makes a layout for it.
void StreamedFrames::streamInto(const std::shared_ptr<const lod::MultiresSource>& pyramid,
                                ValueRange window) {
  layout::StreamingLayout& bricks = gpu_->refinement->layout();
  if (gpu_->channels) {
    if (!bricks.replaceSources(session_.streamedChannels())) return;
  } else {
    auto windowed = std::make_shared<lod::WindowedSource>(pyramid, window);
    if (!bricks.replaceSources({windowed})) return;
    gpu_->technique.upload.pyramid = windowed;
    gpu_->source = std::make_unique<lod::MultiresVolumeSource>(std::move(windowed));
  }
  gpu_->pyramid = pyramid;
  gpu_->frame = nullptr;
  gpu_->frameKey.clear();
  complete_ = false;
  timePoint_ = session_.timePoint();
  ++timePointsStreamedIn_;
}

const gpu::Texture& StreamedFrames::render(int width, int height) {
  checkImageSize(width, height);
  const std::shared_ptr<const lod::MultiresSource> pyramid = session_.sharedPyramid();
  if (!pyramid) throw InputError("no streamed volume is open (a store played over bricks)");
  Settings s = session_.currentSettings();
  s.validate();
  const ValueRange window = s.window.value_or(pyramid->shape().window());
  const int channels = drawsChannels() ? session_.channelView().channels().size() : 0;
  const std::string key = techniqueKey(s, width, height, window, channels);
  session_.device().context->makeCurrent();
  if (gpu_ && gpu_->pyramid != pyramid && gpu_->key == key && reuseLayout) {
    streamInto(pyramid, window);
  }
  if (!gpu_ || gpu_->pyramid != pyramid || gpu_->key != key) {
    makeLayout(pyramid, s, width, height, window, key);
  }
  // The channel view's colours, windows, visibility and mode (its edits
  // are in the settings too, so they change frameKey below).
  if (gpu_->channels) *gpu_->channels = session_.channelView().channels();
  const std::string frameKey = s.toJson().dump();
  if (gpu_->frame && complete_ && frameKey == gpu_->frameKey) return *gpu_->frame;
  RenderRequest req;
  req.settings = s;
  req.width = width;
  req.height = height;
  render::Technique& technique = gpu_->drawn();
  if (gpu_->channels) {
    // As ChannelView draws channels in core.
    technique.setTransferFunction(s.tf);
    req.settings.camera.frame(gpu_->channels->geometry());
    req.settings.render.mode = renderModeFor(gpu_->channels->mode);
  } else {
    prepareFrame(technique, *gpu_->technique.upload.volume, req);  // frames the camera
  }
  last_ = gpu_->refinement->step(req.settings.camera, width, height, req.settings.tf, pace);
  gpu_->frame = &technique.render(req.settings.camera, req.settings.render, width, height, 0.0);
  gpu_->frameKey = frameKey;
  complete_ = last_.complete;
  return *gpu_->frame;
}

bool StreamedFrames::shownComplete(int t) const {
  return gpu_ && gpu_->frame && complete_ && timePoint_ == t &&
         gpu_->pyramid == session_.sharedPyramid();
}

Image StreamedFrames::readImage() const {
  if (!gpu_ || !gpu_->frame) throw InputError("no streamed frame has been rendered");
  session_.device().context->makeCurrent();
  return gpu_->drawn().readImage();
}

void StreamedFrames::close() {
  if (gpu_) session_.device().context->makeCurrent();
  gpu_.reset();
  complete_ = false;
  timePoint_ = -1;
  last_ = {};
}

StreamedFrames& Session::streamedFrames() {
  if (!streamedFrames_) streamedFrames_ = std::make_unique<StreamedFrames>(*this);
  return *streamedFrames_;
}

}  // namespace tessera::session
