#pragma once
// Headless OpenGL ES context through EGL, with no display and no X server:
// Mesa's surfaceless platform (EGL_MESA_platform_surfaceless) first, then
// the device platform (EGL_EXT_platform_device, how NVIDIA's EGL runs
// headless), then the default display.
#include <memory>
#include <string>

#include "tessera/gpu/DeviceCaps.h"
#include "tessera/gpu/MemoryLedger.h"

namespace tessera::gpu {

class GlContext {
 public:
  struct Options {
    ApiLevel api = ApiLevel::Gles3;
    // "auto", "surfaceless", "device" or "default"; env TESSERA_EGL_PLATFORM overrides "auto".
    std::string platform = "auto";
  };

  // Throws GpuError saying which platforms were tried and why they failed.
  static std::unique_ptr<GlContext> createHeadless(const Options& options);
  static std::unique_ptr<GlContext> createHeadless() { return createHeadless(Options{}); }
  // Wraps the context that is current on this thread but was created by
  // someone else (a GLFW window, an Emscripten WebGL canvas): queries its
  // caps, never destroys it, and makeCurrent() leaves it to its owner.
  // `platform` names it ("glfw-egl", "webgl2", ...). See AdoptedGlContext.cpp.
  static std::unique_ptr<GlContext> adoptCurrent(ApiLevel api, const std::string& platform);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  void makeCurrent();
  const DeviceCaps& caps() const { return caps_; }
  MemoryLedger& ledger() { return ledger_; }
  const std::string& platform() const { return platform_; }

 private:
  GlContext() = default;
  void* display_ = nullptr;
  void* context_ = nullptr;
  void* surface_ = nullptr;
  DeviceCaps caps_;
  MemoryLedger ledger_;
  std::string platform_;
};

}  // namespace tessera::gpu
