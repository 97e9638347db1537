// GlfwWindow: a GLFW window whose OpenGL ES context GLFW creates through
// EGL (the same EGL the headless GlContext uses), adopted as a GlContext.
#include "tessera/gpu/GlfwWindow.h"

#include <cstdio>
#include <string>
#include <utility>

#include "tessera/core/Error.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace tessera::gpu {

namespace {

// GLFW reports errors through a callback, not return values: the last one
// goes into the exception that a failed start throws.
std::string& lastGlfwError() {
  static std::string error;
  return error;
}

void recordGlfwError(int code, const char* what) {
  lastGlfwError() = "GLFW error " + std::to_string(code) + ": " + (what ? what : "?");
  std::fprintf(stderr, "tessera: %s\n", lastGlfwError().c_str());
}

std::string withGlfwError(std::string message) {
  if (!lastGlfwError().empty()) message += " (" + lastGlfwError() + ")";
  return message;
}

}  // namespace

GlfwWindow::GlfwWindow(const Options& options) {
  const bool es3 = options.api == ApiLevel::Gles3;
  lastGlfwError().clear();
  glfwSetErrorCallback(recordGlfwError);
  if (!glfwInit()) {
    throw GpuError(
        withGlfwError("GLFW cannot start: no display? (set DISPLAY, or run under xvfb-run -a)"));
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_ES_API);
  glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, es3 ? 3 : 2);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 0);
  window_ =
      glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
  if (!window_) {
    const std::string message =
        withGlfwError(std::string("cannot open a window with an OpenGL ES ") +
                      (es3 ? "3.0" : "2.0") + " context through EGL");
    glfwTerminate();
    throw GpuError(message);
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  glfwSetWindowUserPointer(window_, this);
  try {
    context_ = GlContext::adoptCurrent(options.api, "glfw-egl");
  } catch (...) {
    glfwDestroyWindow(window_);
    glfwTerminate();
    throw;
  }
}

GlfwWindow::~GlfwWindow() {
  context_.reset();
  glfwDestroyWindow(window_);
  glfwTerminate();
}

bool GlfwWindow::shouldClose() const {
  return glfwWindowShouldClose(window_) != 0;
}

void GlfwWindow::requestClose() {
  glfwSetWindowShouldClose(window_, 1);
}

void GlfwWindow::pollEvents() {
  glfwPollEvents();
}

void GlfwWindow::swapBuffers() {
  glfwSwapBuffers(window_);
}

glm::ivec2 GlfwWindow::framebufferSize() const {
  glm::ivec2 size(0);
  glfwGetFramebufferSize(window_, &size.x, &size.y);
  return size;
}

glm::ivec2 GlfwWindow::windowSize() const {
  glm::ivec2 size(0);
  glfwGetWindowSize(window_, &size.x, &size.y);
  return size;
}

double GlfwWindow::seconds() const {
  return glfwGetTime();
}

void GlfwWindow::onDrop(std::function<void(const std::vector<std::string>& paths)> handler) {
  drop_ = std::move(handler);
  glfwSetDropCallback(window_, [](GLFWwindow* w, int count, const char** paths) {
    auto* self = static_cast<GlfwWindow*>(glfwGetWindowUserPointer(w));
    if (count > 0 && self->drop_) self->drop_(std::vector<std::string>(paths, paths + count));
  });
}

}  // namespace tessera::gpu
