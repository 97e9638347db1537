#include "tessera/gpu/GlContext.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <vector>

#include "tessera/core/Error.h"

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

namespace tessera::gpu {

namespace {

std::string eglErrorName(EGLint e) {
  switch (e) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    default:
      return "EGL error " + std::to_string(e);
  }
}

bool hasExtension(const char* list, const std::string& name) {
  if (!list) return false;
  const std::string s = std::string(" ") + list + " ";
  return s.find(" " + name + " ") != std::string::npos;
}

struct Attempt {
  EGLDisplay display = EGL_NO_DISPLAY;
  std::string platform;
};

EGLDisplay surfacelessDisplay(std::string& why) {
  const char* clientExt = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(clientExt, "EGL_MESA_platform_surfaceless")) {
    why = "EGL_MESA_platform_surfaceless not offered";
    return EGL_NO_DISPLAY;
  }
  auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!getPlatformDisplay) {
    why = "eglGetPlatformDisplayEXT missing";
    return EGL_NO_DISPLAY;
  }
  EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (d == EGL_NO_DISPLAY) why = "eglGetPlatformDisplayEXT: " + eglErrorName(eglGetError());
  return d;
}

std::vector<EGLDisplay> deviceDisplays(std::string& why) {
  std::vector<EGLDisplay> out;
  const char* clientExt = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(clientExt, "EGL_EXT_platform_device")) {
    why = "EGL_EXT_platform_device not offered";
    return out;
  }
  auto queryDevices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!queryDevices || !getPlatformDisplay) {
    why = "eglQueryDevicesEXT/eglGetPlatformDisplayEXT missing";
    return out;
  }
  EGLDeviceEXT devices[16];
  EGLint n = 0;
  if (!queryDevices(16, devices, &n) || n == 0) {
    why = "no EGL devices";
    return out;
  }
  for (EGLint i = 0; i < n; ++i) {
    EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (d != EGL_NO_DISPLAY) out.push_back(d);
  }
  if (out.empty()) why = "no display on any of " + std::to_string(n) + " EGL devices";
  return out;
}

}  // namespace

std::unique_ptr<GlContext> GlContext::createHeadless(const Options& options) {
  std::string platform = options.platform;
  if (platform == "auto") {
    if (const char* env = std::getenv("TESSERA_EGL_PLATFORM")) platform = env;
  }
  std::vector<Attempt> candidates;
  std::string report;
  if (platform == "auto" || platform == "surfaceless") {
    std::string why;
    EGLDisplay d = surfacelessDisplay(why);
    if (d != EGL_NO_DISPLAY)
      candidates.push_back({d, "surfaceless"});
    else
      report += " surfaceless: " + why + ";";
  }
  if (platform == "auto" || platform == "device") {
    std::string why;
    for (EGLDisplay d : deviceDisplays(why)) candidates.push_back({d, "device"});
    if (!why.empty()) report += " device: " + why + ";";
  }
  if (platform == "auto" || platform == "default") {
    EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (d != EGL_NO_DISPLAY)
      candidates.push_back({d, "default"});
    else
      report += " default: no display;";
  }
  if (candidates.empty() && report.empty()) {
    throw GpuError("unknown EGL platform '" + platform +
                   "' (expected auto, surfaceless, device or default)");
  }

  const int major = options.api == ApiLevel::Gles3 ? 3 : 2;
  for (const Attempt& a : candidates) {
    EGLint vmaj = 0, vmin = 0;
    if (!eglInitialize(a.display, &vmaj, &vmin)) {
      report += " " + a.platform + ": eglInitialize " + eglErrorName(eglGetError()) + ";";
      continue;
    }
    if (!eglBindAPI(EGL_OPENGL_ES_API)) {
      report += " " + a.platform + ": eglBindAPI(ES) failed;";
      eglTerminate(a.display);
      continue;
    }
    const char* dispExt = eglQueryString(a.display, EGL_EXTENSIONS);
    const EGLint ctxAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, major, EGL_CONTEXT_MINOR_VERSION, 0,
                                 EGL_NONE};
    EGLConfig config = nullptr;  // EGL_NO_CONFIG_KHR
    EGLSurface surface = EGL_NO_SURFACE;
    EGLContext ctx = EGL_NO_CONTEXT;
    // Mesa's surfaceless platform offers no ES3 configs but accepts a
    // config-less context (ENVIRONMENT.md), so try that first.
    if (hasExtension(dispExt, "EGL_KHR_no_config_context") &&
        hasExtension(dispExt, "EGL_KHR_surfaceless_context")) {
      ctx = eglCreateContext(a.display, config, EGL_NO_CONTEXT, ctxAttribs);
    }
    if (ctx == EGL_NO_CONTEXT) {
      const EGLint cfgAttribs[] = {EGL_SURFACE_TYPE,
                                   EGL_PBUFFER_BIT,
                                   EGL_RENDERABLE_TYPE,
                                   major == 3 ? EGL_OPENGL_ES3_BIT : EGL_OPENGL_ES2_BIT,
                                   EGL_RED_SIZE,
                                   8,
                                   EGL_GREEN_SIZE,
                                   8,
                                   EGL_BLUE_SIZE,
                                   8,
                                   EGL_ALPHA_SIZE,
                                   8,
                                   EGL_NONE};
      EGLint n = 0;
      if (eglChooseConfig(a.display, cfgAttribs, &config, 1, &n) && n > 0) {
        ctx = eglCreateContext(a.display, config, EGL_NO_CONTEXT, ctxAttribs);
        if (ctx != EGL_NO_CONTEXT && !hasExtension(dispExt, "EGL_KHR_surfaceless_context")) {
          const EGLint pb[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
          surface = eglCreatePbufferSurface(a.display, config, pb);
        }
      }
    }
    if (ctx == EGL_NO_CONTEXT) {
      report += " " + a.platform + ": eglCreateContext(ES " + std::to_string(major) + ") " +
                eglErrorName(eglGetError()) + ";";
      eglTerminate(a.display);
      continue;
    }
    if (!eglMakeCurrent(a.display, surface, surface, ctx)) {
      report += " " + a.platform + ": eglMakeCurrent " + eglErrorName(eglGetError()) + ";";
      eglDestroyContext(a.display, ctx);
      eglTerminate(a.display);
      continue;
    }
    std::unique_ptr<GlContext> c(new GlContext());
    c->display_ = a.display;
    c->context_ = ctx;
    c->surface_ = surface;
    c->platform_ = a.platform;
    c->caps_ = DeviceCaps::query(options.api);
    return c;
  }
  throw GpuError("cannot create a headless OpenGL ES " + std::to_string(major) +
                 " context through EGL:" + report);
}

GlContext::~GlContext() {
  if (display_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (surface_) eglDestroySurface(display_, surface_);
    if (context_) eglDestroyContext(display_, context_);
    // No eglTerminate: the platform display is shared by every context in
    // the process, and terminating it would invalidate the others.
  }
}

void GlContext::makeCurrent() {
  if (!display_) return;  // adopted: its owner makes it current (adoptCurrent)
  if (eglGetCurrentContext() == context_) return;
  if (!eglMakeCurrent(display_, surface_, surface_, context_)) {
    throw GpuError("eglMakeCurrent failed: " + eglErrorName(eglGetError()));
  }
}

}  // namespace tessera::gpu
