// Session::renderChannels: a multi-channel frame of an OME-Zarr store
// (docs/channels.md) through the ray caster over layout::ChannelLayout, and
// its CPU reference.
#include <chrono>
#include <cstdio>

#include "tessera/io/ZarrChannels.h"
#include "tessera/layout/ChannelLayout.h"
#include "tessera/reference/ChannelReference.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/render/Raycaster.h"
#include "tessera/session/Session.h"

namespace tessera::session {

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string describe(const Channel& c) {
  char s[160];
  std::snprintf(s, sizeof s, "%s %02x%02x%02x %g:%g %s", c.label.c_str(),
                static_cast<unsigned>(c.color.r * 255.0 + 0.5),
                static_cast<unsigned>(c.color.g * 255.0 + 0.5),
                static_cast<unsigned>(c.color.b * 255.0 + 0.5), c.window.min, c.window.max,
                c.visible ? "on" : "off");
  return s;
}

}  // namespace

ChannelFrame Session::renderChannels(const std::string& spec, int width, int height, bool reference,
                                     int time) {
  const Settings& s = settings_;
  s.validate();
  ChannelSet set = readZarrChannels(spec, s.channels.indices, time);
  s.channels.applyTo(set, spec);
  ChannelFrame frame;
  for (const Channel& c : set.channels()) frame.channels.push_back(describe(c));
  Camera camera = s.camera;
  camera.frame(set.geometry());
  gpu::GlContext& gl = *device_.context;
  gl.makeCurrent();
  const auto layout = layout::ChannelLayout::create(set, device_.limits, gl.ledger());
  frame.layout = layout->plan().reason;
  const auto t0 = std::chrono::steady_clock::now();
  {
    render::Raycaster caster(gl, set.geometry(), *layout);
    caster.setSkipBlockSize(0);  // the block grid is one volume's
    caster.setTransferFunction(s.tf);
    RenderSettings render = s.render;
    render.mode = renderModeFor(set.mode);
    frame.image = caster.renderImage(camera, render, width, height);
  }
  frame.gpuMs = msSince(t0);
  if (reference) {
    const auto t1 = std::chrono::steady_clock::now();
    frame.reference = renderChannelsReference(set, s.tf, camera, s.render, width, height);
    frame.referenceMs = msSince(t1);
    frame.psnr = psnr(frame.image, *frame.reference);
  }
  return frame;
}

}  // namespace tessera::session
