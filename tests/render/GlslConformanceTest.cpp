// The shaders Tessera compiles, checked by the Khronos reference compiler
// (glslangValidator) rather than by Mesa alone: Mesa accepts GLSL ES 1.00
// that WebGL 1 and mobile drivers reject (Appendix A: loop forms, sampler
// indexing), so conformance is checked where the rules are enforced.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include <sys/wait.h>

#include "support/GpuTestContext.h"
#include "support/TestSupport.h"
#include "tessera/gpu/Program.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/BricksLayout.h"
#include "tessera/layout/ChannelLayout.h"
#include "tessera/layout/MosaicLayout.h"
#include "tessera/layout/PackedMosaicLayout.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

using namespace tessera;

namespace {

struct Validation {
  int exitCode;
  std::string log;
};

Validation run(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  std::string log;
  std::array<char, 4096> buf{};
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) log.append(buf.data(), n);
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, log};
}

// glslang's default resource limits are permissive; GLSL ES 1.00's
// Appendix A (for-loops of the form "i < constant", samplers and uniforms
// indexed by constant-index expressions only, no while loops) is enforced
// when the "limits" of its configuration are set to 0.
std::string es100Limits() {
  std::string conf = run("glslangValidator -c").log;
  for (const char* key :
       {"nonInductiveForLoops", "whileLoops", "doWhileLoops", "generalUniformIndexing",
        "generalAttributeMatrixVectorIndexing", "generalVaryingIndexing", "generalSamplerIndexing",
        "generalVariableIndexing", "generalConstantMatrixVectorIndexing"}) {
    const std::string on = std::string(key) + " 1";
    const auto at = conf.find(on);
    if (at != std::string::npos) conf.replace(at, on.size(), std::string(key) + " 0");
  }
  return conf;
}

Validation validate(const std::string& source, const std::string& stage) {
  const test::TempDir dir;
  const auto path = dir / ("shader." + stage);
  const auto conf = dir / "es100.conf";
  std::ofstream(path) << source;
  std::ofstream(conf) << es100Limits();
  return run("glslangValidator " + conf.string() + " " + path.string());
}

// Five channels of v (two RGBA textures), for layout::ChannelLayout.
ChannelSet fiveChannels(const Volume& v) {
  ChannelSet set;
  const auto shared = std::make_shared<const Volume>(v);
  for (int i = 0; i < 5; ++i) set.add({.volume = shared, .label = std::to_string(i)});
  return set;
}

bool haveValidator() {
  return std::system("command -v glslangValidator >/dev/null 2>&1") == 0;
}

// The slicing techniques: slice3d on this layout, slice2d with
// every classification, composite and MIP.
void expectSlicingConformant(gpu::GlContext& c, const Volume& v, const layout::Layout& layout) {
  render::Slice3DRenderer slice3d(c, v, layout);
  std::vector<std::string> sources{gpu::assembleShader(slice3d.vertexParts())};
  for (RenderMode mode : {RenderMode::Composite, RenderMode::Mip}) {
    RenderSettings s;
    s.mode = mode;
    sources.push_back(gpu::assembleShader(slice3d.fragmentParts(s)));
    s.shading.enabled = true;  // render/shading.glsl (composite only), render/clipping.glsl
    s.clipping.planes.push_back({});
    sources.push_back(gpu::assembleShader(slice3d.fragmentParts(s)));
    s.shading.enabled = false;
    s.clipping.planes.clear();
    for (auto cls : {render::SliceClassification::Pre, render::SliceClassification::Palette,
                     render::SliceClassification::Post}) {
      if (mode == RenderMode::Mip && cls != render::SliceClassification::Post) continue;
      render::Slice2DRenderer slice2d(c, v, {.classification = cls});
      if (sources.size() == 2) sources.push_back(gpu::assembleShader(slice2d.vertexParts()));
      sources.push_back(gpu::assembleShader(slice2d.fragmentParts(s)));
      if (mode == RenderMode::Composite && cls == render::SliceClassification::Post) {
        RenderSettings shaded = s;
        shaded.shading.enabled = true;
        shaded.clipping.cropMax = {0.5, 1.0, 1.0};
        sources.push_back(gpu::assembleShader(slice2d.fragmentParts(shaded)));
      }
    }
  }
  if (layout.drawsChannels()) {
    sources.push_back(gpu::assembleShader(slice3d.channelResolveParts()));
    // slice2d at the stacks' planes of the channels (docs/channels.md).
    render::Slice2DRenderer slice2d(c, v, {.channels = &layout});
    for (RenderMode mode : {RenderMode::Composite, RenderMode::Mip}) {
      RenderSettings s;
      s.mode = mode;
      sources.push_back(gpu::assembleShader(slice2d.fragmentParts(s)));
    }
    sources.push_back(gpu::assembleShader(slice2d.channelResolveParts()));
    // In an RGBA8 target: slabs of kRgba8SlabPlanes planes, dithered.
    render::Slice2DRenderer slabs(c, v, {.halfFloatAccumulation = false, .channels = &layout});
    sources.push_back(gpu::assembleShader(slabs.fragmentParts(RenderSettings{})));
  }
  for (const std::string& src : sources) {
    const bool vertex = src.find("gl_Position") != std::string::npos;
    const Validation r = validate(src, vertex ? "vert" : "frag");
    EXPECT_EQ(r.exitCode, 0) << layout.name() << ":\n" << r.log;
  }
}

void expectConformant(gpu::GlContext& c, const Volume& v, const layout::Layout& layout) {
  render::Raycaster caster(c, v, layout);
  for (RenderMode mode :
       {RenderMode::Composite, RenderMode::Mip, RenderMode::MinIp, RenderMode::Average}) {
    for (int skip : {0, 8}) {
      caster.setSkipBlockSize(skip);
      for (bool shade : {false, true}) {
        // Composite also pre-integrated and with adaptive steps (the other
        // modes ignore both, docs/sampling.md).
        const int samplings = mode == RenderMode::Composite ? 4 : 1;
        for (int sampling = 0; sampling < samplings; ++sampling) {
          RenderSettings s;
          s.mode = mode;
          s.shading.enabled = shade;
          s.sampling.preintegrate = (sampling & 1) != 0;
          s.sampling.adaptive = (sampling & 2) != 0;
          if (shade) s.clipping.planes.push_back({});  // render/clipping.glsl too
          const Validation frag = validate(gpu::assembleShader(caster.fragmentParts(s)), "frag");
          EXPECT_EQ(frag.exitCode, 0) << layout.name() << " skip " << skip << " shade " << shade
                                      << " sampling " << sampling << ":\n"
                                      << frag.log;
        }
      }
    }
  }
  const Validation vert = validate(gpu::assembleShader(caster.vertexParts()), "vert");
  EXPECT_EQ(vert.exitCode, 0) << vert.log;
  expectSlicingConformant(c, v, layout);
}

}  // namespace

TEST(GlslConformance, Es2ShadersPassTheReferenceCompiler) {
  if (!haveValidator())
    GTEST_SKIP() << "glslangValidator not installed (scripts/setup.sh installs it)";
  gpu::GlContext::Options o;
  o.api = gpu::ApiLevel::Gles2;
  auto c = gpu::GlContext::createHeadless(o);
  const Volume v = makeSheppLogan({37, 53, 29});
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c->caps());
  auto mosaic = layout::MosaicLayout::create(v, limits, c->ledger());
  limits.max2DTextureSize = 128;  // several textures: the sampler if-chain
  auto packed = layout::PackedMosaicLayout::create(v, limits, c->ledger(), 6);
  // Bricks in 14^2-tile mosaics of 128^2: all 8 atlas samplers' if-chain.
  layout::BricksOptions brickOptions;
  brickOptions.brickSize = 12;
  auto bricks = layout::BricksLayout::create(
      std::make_shared<lod::InCoreMultiresSource>(std::make_shared<const Volume>(v)), limits,
      c->ledger(), brickOptions);
  EXPECT_EQ(bricks->textureUnits(), 9) << bricks->plan().reason;
  expectConformant(*c, v, *mosaic);
  expectConformant(*c, v, *packed);
  expectConformant(*c, v, *bricks);
  const ChannelSet five = fiveChannels(v);
  expectConformant(
      *c, v, *layout::ChannelLayout::create(five, gpu::DeviceLimits::of(c->caps()), c->ledger()));
  mosaic.reset();
  packed.reset();
  bricks.reset();
  c.reset();
  test::gpuContext();
}

TEST(GlslConformance, Es3ShadersPassTheReferenceCompiler) {
  if (!haveValidator())
    GTEST_SKIP() << "glslangValidator not installed (scripts/setup.sh installs it)";
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSheppLogan({37, 53, 29});
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  auto t3d = layout::Texture3DLayout::create(v, limits, c.ledger());
  auto mosaic = layout::MosaicLayout::create(v, limits, c.ledger());
  auto bricks = layout::BricksLayout::create(
      std::make_shared<lod::InCoreMultiresSource>(std::make_shared<const Volume>(v)), limits,
      c.ledger());
  expectConformant(c, v, *t3d);
  expectConformant(c, v, *mosaic);
  expectConformant(c, v, *bricks);
  const ChannelSet five = fiveChannels(v);
  expectConformant(c, v, *layout::ChannelLayout::create(five, limits, c.ledger()));
}

// The overlay and hybrid-compositor programs, assembled as
// OverlayRenderer and HybridCompositor assemble them, for both API levels.
TEST(GlslConformance, OverlayAndHybridShadersPassTheReferenceCompiler) {
  if (!haveValidator())
    GTEST_SKIP() << "glslangValidator not installed (scripts/setup.sh installs it)";
  for (gpu::ApiLevel api : {gpu::ApiLevel::Gles2, gpu::ApiLevel::Gles3}) {
    auto part = [](const char* name) { return gpu::embeddedShaderPart(name); };
    const std::vector<std::vector<gpu::ShaderPart>> vertex = {
        {gpu::shaderPreamble(api, false, {}), part("render/overlay.vert.glsl")},
        {gpu::shaderPreamble(api, false, {}), part("render/fullscreen.vert.glsl")}};
    std::vector<std::vector<gpu::ShaderPart>> fragment = {
        {gpu::shaderPreamble(api, true, {}), part("render/camera_ray.glsl"),
         part("render/overlay_color.frag.glsl")},
        {gpu::shaderPreamble(api, true, {}), part("render/overlay_distance.frag.glsl")},
        {gpu::shaderPreamble(api, true, {}), part("render/hybrid_composite.frag.glsl")}};
    for (const char* method : {"METHOD_COPY 1", "METHOD_ALPHA 1", "METHOD_TWO_PASS 1",
                               "METHOD_LUMA_AVG 1", "METHOD_LUMA_601 1"}) {
      fragment.push_back(
          {gpu::shaderPreamble(api, true, {method}), part("render/hybrid_resolve.frag.glsl")});
    }
    for (const auto& parts : vertex) {
      const Validation r = validate(gpu::assembleShader(parts), "vert");
      EXPECT_EQ(r.exitCode, 0) << r.log;
    }
    for (const auto& parts : fragment) {
      const Validation r = validate(gpu::assembleShader(parts), "frag");
      EXPECT_EQ(r.exitCode, 0) << r.log;
    }
  }
}

TEST(GlslConformance, ValidatorRejectsANonConstantLoopInGlslEs100) {
  if (!haveValidator()) GTEST_SKIP() << "glslangValidator not installed";
  // The check has teeth: a loop bounded by a uniform is illegal in ES 1.00.
  const std::string bad =
      "#version 100\nprecision highp float;\nuniform int n;\nvoid main() {\n  float a = 0.0;\n"
      "  for (int i = 0; i < n; ++i) a += 1.0;\n  gl_FragColor = vec4(a);\n}\n";
  EXPECT_NE(validate(bad, "frag").exitCode, 0);
}
