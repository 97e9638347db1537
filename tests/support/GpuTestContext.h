#pragma once
// One headless OpenGL ES 3 context shared by the GPU tests of a suite (made
// current again on each call, in case a test created another context).
#include <memory>

#include "tessera/gpu/GlContext.h"

namespace tessera::test {

inline gpu::GlContext& gpuContext() {
  static std::unique_ptr<gpu::GlContext> context = gpu::GlContext::createHeadless();
  context->makeCurrent();
  return *context;
}

}  // namespace tessera::test
