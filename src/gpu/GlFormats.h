#pragma once
// Private to gpu: the GL enums behind a TexelFormat.
#include <cstdint>

#include "gpu/gl.h"
#include "tessera/gpu/TexelFormat.h"

namespace tessera::gpu {

struct GlFormat {
  GLenum internalFormat;
  GLenum format;
  GLenum type;
  std::uint64_t texelBytes;   // on the GPU
  std::uint64_t uploadBytes;  // per texel in an upload
};

GlFormat glFormat(TexelFormat format);

}  // namespace tessera::gpu
