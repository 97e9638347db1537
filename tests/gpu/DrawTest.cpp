// The GL-free drawing API of gpu (Draw.h, TexelFormat.h, LookupTexture.h):
// each blend rule against its formula, typed textures round-tripping their
// texels, lookup tables in the format each API level gets.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "support/GpuTestContext.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/LookupTexture.h"
#include "tessera/gpu/Program.h"
#include "tessera/gpu/ProgramCache.h"

using namespace tessera;

namespace {

gpu::Program constantColour(gpu::ApiLevel api) {
  const gpu::ShaderPart frag{"constant.frag",
                             "uniform vec4 u_colour;\nvoid main() { FRAG_COLOR = u_colour; }\n"};
  return gpu::Program::build(
      "constant colour",
      {gpu::shaderPreamble(api, false, {}), gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
      {gpu::shaderPreamble(api, true, {}), frag});
}

// Clears a 4x4 target to `target`, draws `source` with `blend`, reads the result.
glm::dvec4 blendOnce(gpu::GlContext& c, gpu::Blend blend, glm::vec4 target, glm::vec4 source) {
  gpu::Framebuffer fb =
      gpu::Framebuffer::create(c.ledger(), "blend test", 4, 4, gpu::TexelFormat::RGBA8);
  fb.bind();
  gpu::apply({});
  gpu::clearColor(target);
  const gpu::Program program = constantColour(c.caps().api);
  program.use();
  program.set("u_colour", source);
  gpu::apply({.blend = blend});
  const gpu::FullscreenTriangle triangle(c.ledger());
  triangle.draw();
  std::array<std::uint8_t, 4 * 16> pixels{};
  gpu::readPixelsRgba8({0, 0, 4, 4}, pixels.data());
  gpu::apply({});
  return glm::dvec4(pixels[20], pixels[21], pixels[22], pixels[23]) / 255.0;
}

void expectNear(glm::dvec4 got, glm::dvec4 want, const char* what) {
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(got[i], want[i], 1.5 / 255.0) << what << " channel " << i;
}

}  // namespace

TEST(Draw, EveryBlendRuleFollowsItsFormula) {
  gpu::GlContext& c = test::gpuContext();
  const glm::dvec4 d(0.2, 0.4, 0.6, 0.5);  // target
  const glm::dvec4 s(0.3, 0.1, 0.2, 0.4);  // source (premultiplied where the rule says so)
  expectNear(blendOnce(c, gpu::Blend::Off, d, s), s, "off");
  expectNear(blendOnce(c, gpu::Blend::Over, d, s), s + (1.0 - s.a) * d, "over");
  expectNear(blendOnce(c, gpu::Blend::FrontToBack, d, s), (1.0 - d.a) * s + d, "front to back");
  const glm::dvec4 straight(glm::dvec3(s) * s.a + glm::dvec3(d) * (1.0 - s.a),
                            s.a * s.a + d.a * (1.0 - s.a));
  expectNear(blendOnce(c, gpu::Blend::StraightAlpha, d, s), straight, "straight alpha");
  expectNear(blendOnce(c, gpu::Blend::Max, d, s), glm::max(d, s), "max");
}

TEST(Draw, TypedTexturesRoundTripTheirTexels) {
  gpu::GlContext& c = test::gpuContext();
  std::vector<std::uint8_t> texels(8 * 4 * 4);
  for (std::size_t i = 0; i < texels.size(); ++i) texels[i] = static_cast<std::uint8_t>(i * 7);
  gpu::Texture t =
      gpu::Texture::create2D(c.ledger(), "rgba8", gpu::TexelFormat::RGBA8, 8, 4, texels.data());
  EXPECT_EQ(t.bytes(), 8u * 4u * 4u);
  EXPECT_EQ(t.format(), gpu::TexelFormat::RGBA8);
  // Replace one 2x2 block, then read everything back through a framebuffer copy.
  const std::array<std::uint8_t, 16> block{255, 0, 0,   255, 0, 255, 0, 255,
                                           0,   0, 255, 255, 9, 9,   9, 9};
  t.updateRegion({3, 1, 0}, {2, 2, 1}, block.data());
  for (int y = 1; y < 3; ++y) {
    for (int x = 3; x < 5; ++x) {
      for (int ch = 0; ch < 4; ++ch) {
        texels[(static_cast<std::size_t>(y) * 8 + x) * 4 + ch] =
            block[(static_cast<std::size_t>(y - 1) * 2 + (x - 3)) * 4 + ch];
      }
    }
  }
  gpu::Framebuffer fb = gpu::Framebuffer::create(c.ledger(), "copy", 8, 4, gpu::TexelFormat::RGBA8);
  fb.bind();
  const gpu::ShaderPart frag{"copy.frag",
                             "uniform sampler2D u_t;\nvoid main() { FRAG_COLOR = "
                             "texelFetch(u_t, ivec2(gl_FragCoord.xy), 0); }\n"};
  const gpu::Program copy =
      gpu::Program::build("copy",
                          {gpu::shaderPreamble(c.caps().api, false, {}),
                           gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
                          {gpu::shaderPreamble(c.caps().api, true, {}), frag});
  copy.use();
  t.bind(0);
  copy.set("u_t", 0);
  gpu::apply({});
  gpu::FullscreenTriangle(c.ledger()).draw();
  std::vector<std::uint8_t> back(texels.size());
  gpu::readPixelsRgba8({0, 0, 8, 4}, back.data());
  EXPECT_EQ(back, texels);
}

TEST(Draw, LookupTablesUseTheMostPreciseFilterableFormat) {
  gpu::GlContext& c = test::gpuContext();
  std::vector<float> rgba(256 * 4);
  for (std::size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<float>(i % 97) / 96.0f;
  gpu::LookupTexture table;
  table.upload(c, rgba, "lookup");
  EXPECT_EQ(table.entries(), 256);
  EXPECT_EQ(table.texture().format(), gpu::TexelFormat::RGBA16F);
  EXPECT_EQ(table.bytes(), 256u * 8u);
  const gpu::Texture* first = &table.texture();
  const auto id = table.texture().id();
  table.upload(c, rgba, "lookup");
  EXPECT_EQ(table.texture().id(), id) << "same size: updated in place";
  EXPECT_EQ(&table.texture(), first);
  EXPECT_EQ(table.uploads(), 2);
  rgba.resize(16 * 4);
  table.upload(c, rgba, "lookup");
  EXPECT_EQ(table.entries(), 16);
  EXPECT_EQ(table.bytes(), 16u * 8u);

  gpu::GlContext::Options options;
  options.api = gpu::ApiLevel::Gles2;
  auto es2 = gpu::GlContext::createHeadless(options);
  gpu::LookupTexture es2Table;
  es2Table.upload(*es2, rgba, "lookup (ES 2)");
  EXPECT_EQ(es2Table.texture().format(), gpu::DeviceLimits::of(es2->caps()).halfFloatTextures
                                             ? gpu::TexelFormat::RgbaHalfUnsized
                                             : gpu::TexelFormat::Rgba8Unsized);
  test::gpuContext();  // current again for the next test
}

TEST(Draw, ProgramCacheBuildsEachKeyOnce) {
  gpu::GlContext& c = test::gpuContext();
  gpu::ProgramCache cache;
  int builds = 0;
  auto build = [&] {
    ++builds;
    return constantColour(c.caps().api);
  };
  const gpu::Program& a = cache.get("a", build);
  const gpu::Program& again = cache.get("a", build);
  cache.get("b", build);
  EXPECT_EQ(&a, &again);
  EXPECT_EQ(builds, 2);
  EXPECT_EQ(cache.size(), 2u);
}
