// GL errors of work that did not ask for them (gpu::DeferredErrorChecks,
// gpu::leaveErrorsUnasked) are reported by the next check or clear, under
// that work's name: a new texture's allocation check, which clears errors
// first, used to lose them, and a later check blamed them on its own work.
// The error here is a read of float pixels from an RGBA8 target
// (GL_INVALID_OPERATION on ES 3), inside a deferred scope so that the read
// does not ask for it itself.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "support/GpuTestContext.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"

using namespace tessera;

namespace {

// The GpuError's message, or "" when `f` threw none.
template <typename F>
std::string gpuErrorOf(F&& f) {
  try {
    f();
  } catch (const GpuError& e) {
    return e.what();
  }
  return "";
}

class GpuErrorChecks : public ::testing::Test {
 protected:
  void SetUp() override { gpu::clearErrors(); }

  gpu::Framebuffer make(const std::string& label) {
    return gpu::Framebuffer::create(context_.get().ledger(), label, 4, 4, gpu::TexelFormat::RGBA8);
  }
  // Leaves a GL error recorded: the caller's deferred scope keeps the read
  // from asking for it.
  void recordAnError() {
    target_ = make("error test");
    target_.bind();
    std::array<float, 4> pixel{};
    gpu::readPixelsRgba32F({0, 0, 1, 1}, pixel.data());
  }
  // The same by work named `what` that ends without asking (a preview that
  // answers input).
  void leaveAnErrorUnasked(const std::string& what) {
    gpu::DeferredErrorChecks deferred(what);
    recordAnError();
  }

 private:
  test::ApiContext context_{gpu::ApiLevel::Gles3};
  gpu::Framebuffer target_;
};

}  // namespace

TEST_F(GpuErrorChecks, ANewTexturesAllocationReportsTheErrorOfWorkLeftUnasked) {
  gpu::DeferredErrorChecks deferred("the scope's passes");
  recordAnError();
  // The allocation clears errors before its own check: that clear reports
  // the scope's error instead of forgetting it.
  const std::string message = gpuErrorOf([&] { make("made after the error"); });
  EXPECT_NE(message.find("the scope's passes"), std::string::npos) << message;
  EXPECT_NE(message.find("GL error 0x0502"), std::string::npos) << message;  // INVALID_OPERATION
  // Reported once: the next allocation and check find nothing.
  EXPECT_EQ(gpuErrorOf([&] {
              make("made after the report");
              deferred.check("the scope's check");
            }),
            "");
}

TEST_F(GpuErrorChecks, ALaterCheckNamesTheUnaskedWorkBeforeItsOwn) {
  leaveAnErrorUnasked("a preview");
  const std::string message = gpuErrorOf([] { gpu::checkErrors("the next strip"); });
  EXPECT_NE(message.find("the next strip (or a preview before it)"), std::string::npos) << message;
  EXPECT_EQ(gpuErrorOf([] { gpu::checkErrors("the strip after"); }), "");
}

TEST_F(GpuErrorChecks, AClearReportsUnaskedWorksErrorsAndOtherwiseForgetsThem) {
  leaveAnErrorUnasked("a preview");
  gpu::leaveErrorsUnasked("a later call");  // the earliest keeps the name
  const std::string message = gpuErrorOf([] { gpu::clearErrors(); });
  EXPECT_NE(message.find("a preview"), std::string::npos) << message;
  EXPECT_EQ(message.find("a later call"), std::string::npos) << message;
  // Work that asked (a scope checked) leaves nothing to report.
  {
    gpu::DeferredErrorChecks deferred("a strip");
    EXPECT_EQ(gpuErrorOf([&] { deferred.check("a strip"); }), "");
  }
  gpu::leaveErrorsUnasked("no error");
  EXPECT_EQ(gpuErrorOf([] { gpu::clearErrors(); }), "");
  // A scope ended by a check names nothing after it: an error left then is
  // forgotten by a clear, as other code's are.
  {
    gpu::DeferredErrorChecks deferred("a frame");
    deferred.check("a frame");
    recordAnError();
  }
  EXPECT_EQ(gpuErrorOf([] { gpu::clearErrors(); }), "");
  EXPECT_EQ(gpuErrorOf([] { gpu::checkErrors("the next call"); }), "");
}
