// The proof that a technique is one class plus one registration: "march",
// a plain ray marcher (every sample, post-classified, no empty-space
// skipping, no adaptive steps) composed from the shared shader parts (rays,
// the layout seam, classification, shading, clipping, compositing), written
// and registered here from a static initialiser. RegistrySuite
// (tests/render/RegistrySuiteTest.cpp) renders it on every layout at both
// API levels in every case with no test edited; its twin is the CPU
// reference with every sample post-classified (honoursSampling = false).
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "support/GpuTestContext.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/LookupTexture.h"
#include "tessera/render/CameraRay.h"
#include "tessera/render/ClippingUniforms.h"
#include "tessera/render/ShadingUniforms.h"
#include "tessera/render/TechniqueRegistry.h"

using namespace tessera;

namespace {

const char* const kName = "march";
constexpr int kLutEntries = 4096;

// The marching loop; everything else comes from the parts every technique
// shares (render/sample.glsl: classifiedSample, lit with SHADING;
// render/clipping.glsl: clipKeeps with CLIPPING).
const char* const kMarchGlsl = R"(
uniform float u_step;
uniform float u_maxSteps;
uniform float u_ert;
uniform vec4 u_background;

void main() {
  vec2 ndc = gl_FragCoord.xy / u_viewport * 2.0 - 1.0;
  vec3 ro;
  vec3 rd;
  cameraRay(ndc, ro, rd);
  vec3 to = ro / u_extent + 0.5;
  vec3 td = rd / u_extent;
  vec2 range = intersectUnitBox(to, safeInverse(td));
  float t0 = max(range.x, 0.0);
  vec4 acc = vec4(0.0);
  float maxValue = -1.0;
  for (int i = 0; i < MAX_STEPS; i++) {
    float k = float(i);
    if (k >= u_maxSteps) break;
    float t = t0 + (k + 0.5) * u_step;
    if (t >= range.y) break;
    vec3 p = to + t * td;
#ifdef CLIPPING
    if (!clipKeeps(p)) continue;
#endif
#ifdef MODE_MIP
    maxValue = max(maxValue, normalizedValue(fieldValue(p)));
#else
    compositeFrontToBack(acc, classifiedSample(p));
    if (acc.a >= u_ert) break;
#endif
  }
#ifdef MODE_MIP
  if (maxValue >= 0.0) acc = vec4(classify(maxValue).rgb, 1.0);
#endif
  FRAG_COLOR = overBackground(acc, u_background);
}
)";

class MarchTechnique final : public render::Technique {
 public:
  MarchTechnique(gpu::GlContext& context, const Volume& volume, const layout::Layout& layout)
      : context_(context), volume_(volume), layout_(layout), triangle_(context.ledger()) {}

  std::string name() const override { return kName; }
  void setTransferFunction(const TransferFunction& tf) override {
    tf_ = tf;
    lutKey_.clear();
  }
  void prepare(const Camera&, const RenderSettings& settings) override {
    checkModes(settings);
    updateLut(settings);
    program(settings);
  }

  const gpu::Texture& render(const Camera& camera, const RenderSettings& settings, int width,
                             int height, double viewAspect) override {
    checkModes(settings);
    updateLut(settings);
    if (target_.id() == 0 || target_.width() != width || target_.height() != height) {
      target_ = gpu::Framebuffer();
      target_ = gpu::Framebuffer::create(context_.ledger(), "march target", width, height,
                                         gpu::rgba8For(context_.caps().api));
    }
    target_.bind();
    const gpu::Program& p = program(settings);
    p.use();
    render::setCameraRayUniforms(
        p, camera, viewAspect > 0.0 ? viewAspect : static_cast<double>(width) / height, width,
        height, volume_.extent());
    p.set("u_step", static_cast<float>(sampleDistance(settings, volume_.spacing())));
    p.set("u_maxSteps", static_cast<float>(settings.maxSteps));
    p.set("u_ert", static_cast<float>(settings.ertThreshold));
    p.set("u_background", glm::vec4(settings.background));
    const layout::ValueMapping m = layout_.rawFromStored();
    const ValueRange w = volume_.window();
    const double ww = w.max - w.min;
    p.set("u_valueScale", static_cast<float>(m.scale / ww));
    p.set("u_valueBias", static_cast<float>((m.offset - w.min) / ww));
    render::setShadingUniforms(p, settings, camera, m.scale / ww, volume_.extent(),
                               volume_.spacing());
    render::setClippingUniforms(p, settings, camera, volume_.extent());
    const int unit = layout_.bindSeam(p, 0);
    lut_.texture().bind(unit);
    p.set("u_tf", unit);
    p.set("u_tfSize", static_cast<float>(kLutEntries));
    triangle_.draw();
    return target_.color();
  }

  Image readImage() const override {
    Image img(target_.width(), target_.height());
    target_.readRgba8(img.rgba().data());
    img.flipVertically();
    return img;
  }
  std::uint64_t ownTextureBytes() const override { return target_.color().bytes() + lut_.bytes(); }

 private:
  // The projections other than MIP are the built-in ray caster's; this one
  // says so instead of drawing something else.
  static void checkModes(const RenderSettings& s) {
    if (s.mode != RenderMode::Composite && s.mode != RenderMode::Mip) {
      throw InputError("the march technique renders composite and MIP only");
    }
  }

  std::vector<std::string> defines(const RenderSettings& s) const {
    std::vector<std::string> d;
    if (s.mode == RenderMode::Mip) d.push_back("MODE_MIP 1");
    render::addShadingDefines(s, d);
    render::addClippingDefines(s, d);
    if (s.nearest) d.push_back("NEAREST 1");
    d.push_back("MAX_STEPS " + std::to_string(s.maxSteps));
    return d;
  }

  // The TF baked for the sample distance (MIP: one classified sample, its
  // opacity for the TF's unit length, as the reference takes it).
  void updateLut(const RenderSettings& s) {
    const double ds =
        s.mode == RenderMode::Mip ? tf_.opacityUnitLength : sampleDistance(s, volume_.spacing());
    const std::string key = std::to_string(ds) + "|" + std::to_string(s.opacityScale);
    if (key == lutKey_) return;
    lutKey_ = key;
    lut_.upload(context_, tf_.bake(kLutEntries, ds, s.opacityScale), "march transfer function");
  }

  const gpu::Program& program(const RenderSettings& s) {
    std::string key;
    for (const std::string& d : defines(s)) key += d + "|";
    if (key != programKey_) {
      const gpu::ApiLevel api = context_.caps().api;
      std::vector<gpu::ShaderPart> fragment = {gpu::shaderPreamble(api, true, defines(s)),
                                               gpu::embeddedShaderPart("render/camera_ray.glsl")};
      for (gpu::ShaderPart& part : layout_.seamParts()) fragment.push_back(std::move(part));
      for (const char* file :
           {"render/classify.glsl", "render/shading.glsl", "render/clipping.glsl",
            "render/sample.glsl", "render/composite.glsl"}) {
        fragment.push_back(gpu::embeddedShaderPart(file));
      }
      fragment.push_back({"march.frag.glsl", kMarchGlsl});
      program_ = gpu::Program::build("march(" + layout_.name() + ")",
                                     {gpu::shaderPreamble(api, false, {}),
                                      gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
                                     fragment);
      programKey_ = key;
    }
    return program_;
  }

  gpu::GlContext& context_;
  const Volume& volume_;
  const layout::Layout& layout_;
  TransferFunction tf_;
  gpu::FullscreenTriangle triangle_;
  gpu::Framebuffer target_;
  gpu::LookupTexture lut_;
  std::string lutKey_;
  gpu::Program program_;
  std::string programKey_;
};

// One unit besides the layout's (the TF table); its target and table.
const bool kRegistered = [] {
  render::TechniqueRegistry::global().add(
      {.name = kName,
       .summary = "plain ray marching, every sample (a test's technique)",
       .honoursSampling = false,
       .scissorsToVolume = true,  // rays that miss the box leave the background
       .requirements = [](const gpu::DeviceLimits&, glm::ivec3,
                          const render::TechniqueOptions& o) -> render::TechniqueRequirements {
         render::TechniqueRequirements r;
         r.textureUnits = 1;
         r.bytes = static_cast<std::uint64_t>(o.imageSize.x) * o.imageSize.y * 4 +
                   static_cast<std::uint64_t>(kLutEntries) * 4 * 4;
         return r;
       },
       .create = [](const render::TechniqueSetup& s) -> std::unique_ptr<render::Technique> {
         return std::make_unique<MarchTechnique>(s.context, s.volume, *s.layout);
       }});
  return true;
}();

}  // namespace

// Registered before main, after the built-ins (which keep their order).
TEST(RegistryExtension, TheMarchTechniqueIsRegisteredAfterTheBuiltIns) {
  ASSERT_TRUE(kRegistered);
  const std::vector<std::string> names = render::TechniqueRegistry::global().names();
  ASSERT_GE(names.size(), 4u);
  EXPECT_EQ(names[0], "raycast");
  const render::TechniqueEntry& e = render::TechniqueRegistry::global().find(kName);
  EXPECT_FALSE(e.honoursSampling);
  EXPECT_TRUE(e.scissorsToVolume);
  EXPECT_TRUE(e.requirements({}, {32, 32, 32}, {}).ownStorage.empty());
  EXPECT_NE(render::TechniqueRegistry::global().describe().find(kName), std::string::npos);
}
