#pragma once
// Reading a render target back: GL returns the bottom row first, images are
// written top row first.
#include "tessera/core/Image.h"
#include "tessera/gpu/GlObjects.h"

namespace tessera::render {

// The colour attachment of `target` as RGBA8, top row first.
inline Image readImage(const gpu::Framebuffer& target) {
  Image img(target.width(), target.height());
  target.readRgba8(img.rgba().data());
  img.flipVertically();
  return img;
}

}  // namespace tessera::render
