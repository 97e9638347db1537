// ChannelView: the channel lists' one path to a multi-channel frame
// (docs/channels.md). The frame is the one Session::renderChannels draws
// for the same settings (the technique they name — raycast, slice3d or
// slice2d — over layout::ChannelLayout), kept on the GPU between edits.
#include "tessera/session/ChannelView.h"

#include <algorithm>
#include <sstream>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/ZarrChannels.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/layout/ChannelLayout.h"
#include "tessera/render/HybridCompositor.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/ChannelTechnique.h"
#include "tessera/session/Session.h"

namespace tessera::session {

struct ChannelView::Gpu {
  std::unique_ptr<layout::ChannelLayout> layout;
  std::unique_ptr<render::Technique> technique;  // made at the first frame
  std::string techniqueKey;                      // its name and options
  const gpu::Texture* frame = nullptr;
  std::string tfKey;
  std::unique_ptr<render::HybridCompositor> compositor;  // present()'s, made on first use

  // The technique the settings name, as Session::renderChannels makes it
  // (channelTechnique refuses one that cannot draw channels).
  void makeTechnique(gpu::DeviceSession& device, const ChannelSet& set, const Settings& s,
                     int width, int height);
};

namespace {

// The technique a frame is drawn with: its name and the options it reads.
std::string channelTechniqueKey(const Settings& s) {
  return s.technique + '|' + std::to_string(s.lutSize) + '|' + std::to_string(s.slices) + '|' +
         s.classify + '|' + s.gradient;
}

// What a frame depends on besides the channels' own state.
std::string frameKey(const Settings& s, const Camera& c, int width, int height) {
  std::ostringstream key;
  key.precision(17);
  key << width << 'x' << height << '|' << c.azimuthDeg << ',' << c.elevationDeg << ',' << c.zoom
      << ',' << c.fovYDeg << ',' << static_cast<int>(c.projection) << ',' << c.target.x << ','
      << c.target.y << ',' << c.target.z << '|' << s.render.stepVoxels << ','
      << s.render.opacityScale << ',' << s.render.ertThreshold << s.render.jitter << ','
      << s.render.background.r << s.render.background.g << s.render.background.b << '|'
      << channelTechniqueKey(s);
  return key.str();
}

}  // namespace

void ChannelView::Gpu::makeTechnique(gpu::DeviceSession& device, const ChannelSet& set,
                                     const Settings& s, int width, int height) {
  const render::TechniqueEntry& entry = channelTechnique(s.technique);
  render::TechniqueOptions options = s.techniqueOptions({width, height});
  options.skipBlock = 0;  // the block grid is one volume's
  frame = nullptr;
  technique.reset();
  tfKey.clear();
  techniqueKey.clear();
  technique = render::TechniqueRegistry::global().create(
      entry.name, {*device.context, device.limits, set.geometry(), layout.get(), options});
  techniqueKey = channelTechniqueKey(s);
}

ChannelView::ChannelView(Session& session) : session_(session) {}
ChannelView::~ChannelView() = default;

bool ChannelView::open(const std::string& spec, int time) {
  if (!isZarrStore(spec)) return false;
  const ZarrStore store(openZarrStorage(spec));
  if (store.channelCount() < 2) return false;
  const std::vector<int> indices = session_.settings().channels.indices;
#ifndef __EMSCRIPTEN__
  // Native only, as openStreamedSeries: the page draws its streamed stores itself.
  if (session_.streamedSeries() && session_.streamed() && session_.name() == spec) {
    ChannelSet set = session_.streamChannels(indices);
    if (set.size() < 2) return false;
    showOverBricks(std::move(set), spec);
    return true;
  }
#endif
  const int count = store.timePoints();
  if (count < 2) {
    series_.reset();
    time_ = 0;
    show(readZarrChannels(spec, indices, time), spec);
    return true;
  }
  showSeries(
      count, readZarrChannels(spec, indices, time),
      [spec, indices](int t) { return readZarrChannels(spec, indices, t); }, spec, time);
  return true;
}

void ChannelView::showSeries(int count, ChannelSet first, ChannelSeries::Reader read,
                             const std::string& name, int time, TimeSeries::Reading reading,
                             TimeSeries::Arrival arrived, int ahead) {
  if (count < 2) throw InputError(name + ": one time point, not a time series");
  if (time < 0 || time >= count) {
    throw InputError(name + ": time point " + std::to_string(time) + " asked for, the series has " +
                     std::to_string(count) + " (0.." + std::to_string(count - 1) + ")");
  }
  // As many time points held as a quarter of the host budget holds (the
  // series reads the first one again, once, as the start of its window).
  const int keep = TimeSeries::keepWithin(HostBudget::global().limitBytes() / 4,
                                          ChannelSeries::bytes(first), count);
  auto series = std::make_unique<ChannelSeries>(count, std::move(read), keep, reading);
  if (arrived) series->series().setArrival(std::move(arrived), std::clamp(ahead, 1, keep));
  show(std::move(first), name);
  series_ = std::move(series);
  time_ = time;
  series_->want(time);  // reads ahead from here
}

bool ChannelView::showTime(int t) {
  if (!series_) throw InputError("no channels of a time series are shown");
  if (t == time_ && set_) {
    series_->want(t);
    return true;
  }
  std::shared_ptr<const ChannelSet> set = series_->want(t);
  if (!set) return false;
  // The same channels at another time: the camera, colours, windows and
  // visibility are the settings' and stay.
  show(*set, name_);
  time_ = t;
  return true;
}

void ChannelView::showOverBricks(ChannelSet set, const std::string& name) {
  ChannelSettings& c = session_.settings().channels;
  c.applyTo(set, name);
  if (gpu_) session_.device().context->makeCurrent();
  gpu_.reset();
  series_.reset();  // the session's streamed series plays them
  set_ = std::make_unique<ChannelSet>(std::move(set));
  overBricks_ = true;
  name_ = name;
  c.enabled = true;
  c.mode = set_->mode;
  edited();
}

int ChannelView::timePoint() const {
  return overBricks_ ? session_.timePoint() : time_;
}

void ChannelView::show(ChannelSet set, const std::string& name) {
  overBricks_ = false;
  ChannelSettings& c = session_.settings().channels;
  c.applyTo(set, name);
  auto owned = std::make_unique<ChannelSet>(std::move(set));
  gpu::DeviceSession& device = session_.device();
  device.context->makeCurrent();
  auto gpu = std::make_unique<Gpu>();
  gpu->layout = layout::ChannelLayout::create(*owned, device.limits, device.context->ledger());
  gpu_.reset();  // the old layout before the old set it reads
  set_ = std::move(owned);
  gpu_ = std::move(gpu);
  name_ = name;
  c.enabled = true;
  c.mode = set_->mode;
  edited();
}

void ChannelView::close() {
  if (gpu_) session_.device().context->makeCurrent();
  gpu_.reset();
  set_.reset();
  series_.reset();
  time_ = 0;
  overBricks_ = false;
  name_.clear();
  session_.settings().channels.enabled = false;
  edited();
}

// The GPU objects go first (the layout reads the set); on a lost context
// their deletion only raises GL errors, which the caller clears.
std::optional<ChannelView::Shown> ChannelView::takeShown() {
  // Over bricks the set holds no voxels: the session streams them again.
  if (!set_ || overBricks_) return std::nullopt;
  gpu_.reset();
  Shown shown{std::move(*set_), std::move(name_)};
  set_.reset();
  name_.clear();
  ++revision_;
  frameKey_.clear();
  return shown;
}

const ChannelSet& ChannelView::channels() const {
  if (!set_) throw InputError("no channels are shown");
  return *set_;
}

void ChannelView::requireOpen(int i) const {
  const int n = channels().size();
  if (i < 0 || i >= n) {
    throw InputError(name_ + ": channel " + std::to_string(i) + " is outside the " +
                     std::to_string(n) + " channels shown (0.." + std::to_string(n - 1) + ")");
  }
}

// The settings' lists hold one entry per channel shown once any is edited,
// so that a saved state reproduces the frame.
void ChannelView::edited() {
  ++revision_;
  frameKey_.clear();
  if (!set_) return;
  ChannelSettings& c = session_.settings().channels;
  c.colors.clear();
  c.windows.clear();
  c.visible.clear();
  for (const Channel& ch : set_->channels()) {
    c.colors.push_back(ch.color);
    c.windows.push_back(ch.window);
    c.visible.push_back(ch.visible);
  }
  c.mode = set_->mode;
}

void ChannelView::setColor(int i, glm::dvec3 rgb) {
  requireOpen(i);
  for (int k = 0; k < 3; ++k) {
    if (!(rgb[k] >= 0.0 && rgb[k] <= 1.0)) {
      throw InputError("channel colour component " + std::to_string(rgb[k]) + ": expected 0..1");
    }
  }
  (*set_)[i].color = rgb;
  edited();
}

void ChannelView::setWindow(int i, ValueRange window) {
  requireOpen(i);
  if (!(window.max > window.min)) {
    throw InputError("channel " + std::to_string(i) + " window " + std::to_string(window.min) +
                     ".." + std::to_string(window.max) + ": expected LO < HI");
  }
  (*set_)[i].window = window;
  edited();
}

void ChannelView::setVisible(int i, bool visible) {
  requireOpen(i);
  (*set_)[i].visible = visible;
  edited();
}

void ChannelView::setMode(ChannelMode mode) {
  channels();
  set_->mode = mode;
  edited();
}

const gpu::Texture& ChannelView::render(int width, int height) {
  const ChannelSet& set = channels();
  if (overBricks_) return session_.streamedFrames().render(width, height);
  const Settings s = session_.currentSettings();
  Camera camera = s.camera;
  camera.frame(set.geometry());
  const std::string key = frameKey(s, camera, width, height);
  const std::string tfKey = s.tf.toJson();
  if (gpu_->frame && key == frameKey_ && tfKey == gpu_->tfKey) return *gpu_->frame;
  session_.device().context->makeCurrent();
  if (channelTechniqueKey(s) != gpu_->techniqueKey) {
    gpu_->makeTechnique(session_.device(), set, s, width, height);
  }
  if (tfKey != gpu_->tfKey) {
    gpu_->technique->setTransferFunction(s.tf);
    gpu_->tfKey = tfKey;
  }
  RenderSettings render = s.render;
  render.mode = renderModeFor(set.mode);
  gpu_->frame = &gpu_->technique->render(camera, render, width, height, 0.0);
  frameKey_ = key;
  return *gpu_->frame;
}

Image ChannelView::readImage() const {
  if (overBricks_) return session_.streamedFrames().readImage();
  if (!gpu_ || !gpu_->frame) throw InputError("no channel frame has been rendered");
  session_.device().context->makeCurrent();
  return gpu_->technique->readImage();
}

void ChannelView::present(unsigned framebuffer, glm::ivec4 box) {
  if (!gpu_ || !gpu_->frame) throw InputError("no channel frame has been rendered");
  gpu::GlContext& gl = *session_.device().context;
  gl.makeCurrent();
  if (!gpu_->compositor) gpu_->compositor = std::make_unique<render::HybridCompositor>(gl);
  // No lines: the frame (its background composited already) scaled into the box.
  const Settings s = session_.currentSettings();
  gpu_->compositor->composeInto(*gpu_->frame, s.camera, glm::vec4(s.render.background),
                                set_->geometry().extent(), framebuffer, box);
}

}  // namespace tessera::session

namespace tessera::session {

ChannelView& Session::channelView() {
  if (!channelView_) channelView_ = std::make_unique<ChannelView>(*this);
  return *channelView_;
}

}  // namespace tessera::session
