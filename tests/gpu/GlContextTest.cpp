#include <gtest/gtest.h>

#include <GLES3/gl3.h>

#include "support/GpuTestContext.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/Program.h"

using namespace tessera;
using namespace tessera::gpu;

namespace {
GlContext& context() {
  return test::gpuContext();
}
}  // namespace

TEST(GlContext, HeadlessContextReportsEs3Caps) {
  GlContext& c = context();
  EXPECT_FALSE(c.caps().renderer.empty());
  EXPECT_NE(c.caps().version.find("OpenGL ES 3"), std::string::npos) << c.caps().version;
  EXPECT_GE(c.caps().max2DTextureSize, 2048);
  EXPECT_GE(c.caps().max3DTextureSize, 256);
  EXPECT_GE(c.caps().maxTextureUnits, 8);
  EXPECT_FALSE(c.caps().extensions.empty());
}

TEST(GlContext, Es2ContextCanBeCreated) {
  GlContext::Options o;
  o.api = ApiLevel::Gles2;
  auto c = GlContext::createHeadless(o);
  EXPECT_EQ(c->caps().api, ApiLevel::Gles2);
  EXPECT_NE(c->caps().version.find("OpenGL ES"), std::string::npos);
  EXPECT_EQ(c->caps().max3DTextureSize, 0);  // the ES2 feature level has no 3D textures
  context();                                 // restore the shared ES3 context for the other tests
}

TEST(GlContext, FramebufferClearReadsBackExactColour) {
  GlContext& c = context();
  Framebuffer fb = Framebuffer::create(c.ledger(), "test", 16, 8);
  fb.bind();
  glClearColor(1.0f, 0.5f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  std::vector<std::uint8_t> px(16 * 8 * 4);
  fb.readRgba8(px.data());
  for (std::size_t i = 0; i < px.size(); i += 4) {
    ASSERT_EQ(px[i], 255);
    ASSERT_NEAR(px[i + 1], 128, 1);
    ASSERT_EQ(px[i + 2], 0);
    ASSERT_EQ(px[i + 3], 255);
  }
}

TEST(MemoryLedger, CountsEveryTextureAndBufferWhileAlive) {
  GlContext& c = context();
  const std::uint64_t before = c.ledger().totalBytes();
  {
    Texture t = Texture::create3D(c.ledger(), "t3", TexelFormat::R8, 8, 4, 2);
    Texture lut = Texture::create2D(c.ledger(), "lut", TexelFormat::RGBA16F, 256, 1);
    Buffer b =
        Buffer::create(c.ledger(), "vbo", BufferKind::Vertices, 1000, nullptr, BufferUsage::Static);
    EXPECT_EQ(c.ledger().totalBytes() - before, 8u * 4 * 2 + 256u * 8 + 1000u);
    Texture moved = std::move(t);
    EXPECT_EQ(c.ledger().totalBytes() - before, 8u * 4 * 2 + 256u * 8 + 1000u);
  }
  EXPECT_EQ(c.ledger().totalBytes(), before);
}

TEST(MemoryLedger, BudgetRefusesAllocationWithNumbers) {
  MemoryLedger ledger;
  ledger.setBudget(1000);
  ledger.add(GpuResource::Texture, 600, "a");
  try {
    ledger.add(GpuResource::Texture, 600, "volume");
    FAIL() << "expected BudgetError";
  } catch (const BudgetError& e) {
    EXPECT_NE(std::string(e.what()).find("volume"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("budget"), std::string::npos);
  }
}

TEST(Program, CompileErrorNamesShaderPartAndLine) {
  context();
  const ShaderPart vs{
      "test.vert.glsl",
      "in vec2 a_position;\nvoid main() { gl_Position = vec4(a_position, 0.0, 1.0); }\n"};
  const ShaderPart good{"good.glsl", "float f() { return 1.0; }\n"};
  const ShaderPart bad{"broken.frag.glsl",
                       "out vec4 o;\nvoid main() {\n  o = vec4(undefinedThing);\n}\n"};
  try {
    Program::build("t", {shaderPreamble(ApiLevel::Gles3, false, {}), vs},
                   {shaderPreamble(ApiLevel::Gles3, true, {}), good, bad});
    FAIL() << "expected GpuError";
  } catch (const GpuError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("broken.frag.glsl:3"), std::string::npos) << m;
  }
}

TEST(Program, EmbeddedShadersAreFoundByPath) {
  EXPECT_NE(embeddedShaderPart("render/raycast.frag.glsl").text.find("sampleVolume"),
            std::string::npos);
  EXPECT_THROW(embeddedShaderPart("render/none.glsl"), GpuError);
}

TEST(GlContext, DevicePlatformContextRendersLikeSurfaceless) {
  // EGL_EXT_platform_device is how NVIDIA's EGL runs without a display; Mesa
  // offers it too (a software device), so the path is exercised here.
  GlContext::Options o;
  o.platform = "device";
  std::unique_ptr<GlContext> c;
  try {
    c = GlContext::createHeadless(o);
  } catch (const GpuError& e) {
    GTEST_SKIP() << e.what();
  }
  EXPECT_EQ(c->platform(), "device");
  Framebuffer fb = Framebuffer::create(c->ledger(), "device", 4, 4);
  fb.bind();
  glClearColor(0.0f, 1.0f, 0.0f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  std::vector<std::uint8_t> px(4 * 4 * 4);
  fb.readRgba8(px.data());
  EXPECT_EQ(px[1], 255);
  EXPECT_EQ(px[0], 0);
  fb = Framebuffer();
  c.reset();
  context();
}

TEST(GlContext, UnknownPlatformIsAClearError) {
  GlContext::Options o;
  o.platform = "bogus";
  try {
    GlContext::createHeadless(o);
    FAIL();
  } catch (const GpuError& e) {
    EXPECT_NE(std::string(e.what()).find("bogus"), std::string::npos);
  }
  context();
}
