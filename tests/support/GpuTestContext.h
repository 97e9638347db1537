#pragma once
// One headless OpenGL ES 3 context shared by the GPU tests of a suite (made
// current again on each call, in case a test created another context), and
// contexts of a chosen API level for tests that run on ES 3.0 and ES 2.0.
#include <memory>

#include "tessera/gpu/GlContext.h"

namespace tessera::test {

inline gpu::GlContext& gpuContext() {
  static std::unique_ptr<gpu::GlContext> context = gpu::GlContext::createHeadless();
  context->makeCurrent();
  return *context;
}

inline const char* apiName(gpu::ApiLevel api) {
  return api == gpu::ApiLevel::Gles2 ? "gles2" : "gles3";
}

// A context of `api` for one test: the shared ES 3 context, or a fresh ES 2
// one that lives as long as this object. Declare it before the GL objects
// made on it, so that they go first; the shared context is current again
// when it goes.
class ApiContext {
 public:
  explicit ApiContext(gpu::ApiLevel api) {
    gpu::GlContext::Options o;
    o.api = api;
    if (api == gpu::ApiLevel::Gles2) owned_ = gpu::GlContext::createHeadless(o);
  }
  ~ApiContext() {
    owned_.reset();
    gpuContext();
  }
  ApiContext(const ApiContext&) = delete;
  ApiContext& operator=(const ApiContext&) = delete;

  gpu::GlContext& get() { return owned_ ? *owned_ : gpuContext(); }

 private:
  std::unique_ptr<gpu::GlContext> owned_;
};

// Runs body(context) on a context of `api` (see ApiContext).
template <class Body>
void withApi(gpu::ApiLevel api, Body body) {
  ApiContext context(api);
  body(context.get());
}

}  // namespace tessera::test
