#pragma once
// The browser's GL context: a WebGL context on one of the page's canvases,
// created and destroyed here (the web build's twin of
// GlContext::createHeadless; defined in src/gpu/GlContextWebGL.cpp, which
// only the emscripten build compiles). The gpu::GlContext it holds adopts
// the WebGL context (platform "webgl2" or "webgl1").
#include <cstdint>
#include <memory>
#include <string>

#include "tessera/gpu/GlContext.h"

namespace tessera::gpu {

class WebGlContext {
 public:
  // A WebGL 2 (webglVersion 2) or WebGL 1 context on the canvas named by a
  // CSS selector ("#canvas"), made current. Throws GpuError naming the
  // version and canvas when the browser offers none.
  WebGlContext(const std::string& canvasSelector, int webglVersion);
  // Destroys the WebGL context (after whatever used it).
  ~WebGlContext();
  WebGlContext(const WebGlContext&) = delete;
  WebGlContext& operator=(const WebGlContext&) = delete;

  GlContext& gl() { return *context_; }
  int webglVersion() const { return version_; }
  void makeCurrent();
  // Whether the browser took the context away: at once when it does, a
  // task before its webglcontextlost event (GL calls then only fail).
  bool lost() const;

 private:
  std::intptr_t handle_ = 0;
  int version_ = 0;
  std::unique_ptr<GlContext> context_;
};

}  // namespace tessera::gpu
