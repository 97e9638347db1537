#pragma once
// What the desktop panels' tests compare: frames pixel by pixel, the 3D
// view's frame as the window draws it, and a volume's voxels.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>

#include "tessera/core/Image.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/session/Session.h"

namespace tessera::test {

inline constexpr int kPanelFrameSize = 96;

// Pixels whose colour differs by more than `tol` in any component.
inline int differingPixels(const Image& a, const Image& b, int tol = 0) {
  EXPECT_EQ(a.width(), b.width());
  EXPECT_EQ(a.height(), b.height());
  int n = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      const std::uint8_t *p = a.pixel(x, y), *q = b.pixel(x, y);
      for (int c = 0; c < 3; ++c) {
        if (std::abs(int(p[c]) - int(q[c])) > tol) {
          ++n;
          break;
        }
      }
    }
  }
  return n;
}

// The 3D view's frame (session::Session::view(), what the window draws) at
// full quality, without the bounding box and axes the window adds.
inline Image viewFrame(session::Session& session, int size = kPanelFrameSize) {
  viewer::Viewer& v = session.view();
  v.quality = viewer::Quality::Full;
  v.showBoundingBox = false;
  v.showAxes = false;
  gpu::Framebuffer fb =
      gpu::Framebuffer::create(session.device().context->ledger(), "panel test view", size, size);
  v.render(size, size, fb.id());
  Image img(size, size);
  fb.readRgba8(img.rgba().data());
  return img;
}

// Voxels of `a` and `b` that differ (and a failure when the dims do).
inline std::size_t differingVoxels(const Volume& a, const Volume& b) {
  EXPECT_EQ(a.dims(), b.dims());
  if (a.dims() != b.dims()) return a.voxelCount();
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.voxelCount(); ++i) n += a.valueAtIndex(i) != b.valueAtIndex(i);
  return n;
}

}  // namespace tessera::test
