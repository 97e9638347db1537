// GlContext::adoptCurrent lives apart from the EGL code so that a front end
// with its own context (GLFW window, WebGL canvas) reads as its own seam.
#include "gpu/gl.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"

namespace tessera::gpu {

std::unique_ptr<GlContext> GlContext::adoptCurrent(ApiLevel api, const std::string& platform) {
  if (glGetString(GL_VERSION) == nullptr) {
    throw GpuError("no current OpenGL ES context to adopt (" + platform + ")");
  }
  std::unique_ptr<GlContext> c(new GlContext());
  c->platform_ = platform;
  c->caps_ = DeviceCaps::query(api);
  return c;
}

}  // namespace tessera::gpu
