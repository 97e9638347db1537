// gpu::GlContext on the browser platform (replaces GlContext.cpp, the EGL
// platform, in the web build: cmake/Web.cmake), and the page's WebGL
// context (WebGlContext.h), created here so that every GL context creation
// stays in the gpu layer. The native build compiles this file empty.
#ifdef __EMSCRIPTEN__
#include <emscripten/html5.h>

#include <string>

#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/WebGlContext.h"

namespace tessera::gpu {

std::unique_ptr<GlContext> GlContext::createHeadless(const Options&) {
  throw GpuError("no headless OpenGL ES in the browser: the page's canvas provides the context");
}

GlContext::~GlContext() = default;  // WebGlContext destroys the WebGL context

void GlContext::makeCurrent() {}  // WebGlContext::makeCurrent does

WebGlContext::WebGlContext(const std::string& canvasSelector, int webglVersion) {
  EmscriptenWebGLContextAttributes attrs;
  emscripten_webgl_init_context_attributes(&attrs);
  attrs.majorVersion = webglVersion >= 2 ? 2 : 1;
  attrs.minorVersion = 0;
  attrs.alpha = false;
  attrs.depth = false;
  attrs.stencil = false;
  attrs.antialias = false;
  // The page and its tests read the canvas after the frame.
  attrs.preserveDrawingBuffer = true;
  attrs.enableExtensionsByDefault = true;
  const EMSCRIPTEN_WEBGL_CONTEXT_HANDLE h =
      emscripten_webgl_create_context(canvasSelector.c_str(), &attrs);
  if (h <= 0) {
    throw GpuError("this browser offers no WebGL " + std::to_string(attrs.majorVersion) +
                   " context on the canvas " + canvasSelector);
  }
  handle_ = static_cast<std::intptr_t>(h);
  version_ = attrs.majorVersion;
  emscripten_webgl_make_context_current(h);
  const ApiLevel api = version_ == 2 ? ApiLevel::Gles3 : ApiLevel::Gles2;
  try {
    context_ = GlContext::adoptCurrent(api, version_ == 2 ? "webgl2" : "webgl1");
  } catch (...) {
    emscripten_webgl_destroy_context(h);
    throw;
  }
}

WebGlContext::~WebGlContext() {
  context_.reset();
  emscripten_webgl_destroy_context(static_cast<EMSCRIPTEN_WEBGL_CONTEXT_HANDLE>(handle_));
}

void WebGlContext::makeCurrent() {
  emscripten_webgl_make_context_current(static_cast<EMSCRIPTEN_WEBGL_CONTEXT_HANDLE>(handle_));
}

bool WebGlContext::lost() const {
  return emscripten_is_webgl_context_lost(static_cast<EMSCRIPTEN_WEBGL_CONTEXT_HANDLE>(handle_));
}

}  // namespace tessera::gpu
#endif  // __EMSCRIPTEN__
