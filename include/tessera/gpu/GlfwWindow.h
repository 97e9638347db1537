#pragma once
// A desktop window with an OpenGL ES context through GLFW (on EGL): the
// windowed twin of GlContext::createHeadless, so that context creation stays
// in the gpu layer and a desktop front end only draws and handles input.
// Built into tessera_gpu_glfw, and only where GLFW is found
// (cmake/DesktopViewer.cmake): tessera_gpu itself never needs GLFW. GLFW is
// process-wide, so one GlfwWindow exists at a time.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "tessera/gpu/DeviceCaps.h"
#include "tessera/gpu/GlContext.h"

struct GLFWwindow;

namespace tessera::gpu {

class GlfwWindow {
 public:
  struct Options {
    int width = 1280;
    int height = 800;
    std::string title = "Tessera";
    ApiLevel api = ApiLevel::Gles3;  // ES 3.0 or ES 2.0 context
  };

  // Starts GLFW, opens the window, makes its context current (vsync on) and
  // adopts it as context() ("glfw-egl"). Throws GpuError saying what to do
  // when there is no display, or which context could not be made and why.
  explicit GlfwWindow(const Options& options);
  // Destroys the context's owner (the window) and stops GLFW: whatever holds
  // GL objects of context() must be gone before.
  ~GlfwWindow();
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;

  GlContext& context() { return *context_; }
  // For input and GUI libraries that bind to GLFW (Dear ImGui's backend).
  GLFWwindow* handle() const { return window_; }

  bool shouldClose() const;
  void requestClose();
  // Runs the callbacks of what happened since the last call (input, drops).
  void pollEvents();
  void swapBuffers();
  glm::ivec2 framebufferSize() const;  // pixels
  glm::ivec2 windowSize() const;       // screen units (differ on high-DPI screens)
  double seconds() const;              // since GLFW started
  // Called from pollEvents() with the paths dropped on the window at once,
  // in GLFW's order.
  void onDrop(std::function<void(const std::vector<std::string>& paths)> handler);

 private:
  GLFWwindow* window_ = nullptr;
  std::unique_ptr<GlContext> context_;
  std::function<void(const std::vector<std::string>&)> drop_;
};

}  // namespace tessera::gpu
