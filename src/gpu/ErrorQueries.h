#pragma once
// Private to gpu: every glGetError goes through here, counted
// (gpu::errorQueries: in a browser each is a round trip to the GPU process).
#include "gpu/gl.h"

namespace tessera::gpu {

GLenum queryError();

}  // namespace tessera::gpu
