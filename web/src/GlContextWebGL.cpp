// gpu::GlContext on the browser platform (replaces src/gpu/GlContext.cpp,
// the EGL platform, in the web build; see cmake/Web.cmake). The only context
// in a page is the canvas's WebGL context, which the page creates and
// GlContext::adoptCurrent wraps; there is no headless EGL to create one.
#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"

namespace tessera::gpu {

std::unique_ptr<GlContext> GlContext::createHeadless(const Options&) {
  throw GpuError("no headless OpenGL ES in the browser: the page's canvas provides the context");
}

GlContext::~GlContext() = default;  // the canvas owns the WebGL context

void GlContext::makeCurrent() {}  // one context per page, current since adoption

}  // namespace tessera::gpu
