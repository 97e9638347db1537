// The technique registry, and the proof that adding a technique is one file
// plus its registration: an "x-ray" technique (the mean normalised value
// along each ray) is written and registered here, in the test, and rendered
// through the calls `tessera render` makes (gpu::openDevice,
// render::createTechnique, Technique::render / readImage) on a 3D-texture
// and on a 2D layout; its images match the same average computed on the CPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "support/GpuTestContext.h"
#include "support/TestCameras.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/io/Procedural.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/CameraRay.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"
#include "tessera/render/TechniqueRegistry.h"

using namespace tessera;

namespace {

constexpr float kStepFactor = 1.0f;  // samples one voxel (of the smallest spacing) apart

// The mean of the normalised values along the ray, in [0,1] (the classic
// digitally reconstructed radiograph look, without a TF), opaque grey.
const char* kXRayGlsl = R"(
uniform float u_step;
uniform float u_valueScale;
uniform float u_valueBias;

void main() {
  vec2 ndc = gl_FragCoord.xy / u_viewport * 2.0 - 1.0;
  vec3 ro;
  vec3 rd;
  cameraRay(ndc, ro, rd);
  vec3 to = ro / u_extent + 0.5;
  vec3 td = rd / u_extent;
  vec2 range = intersectUnitBox(to, safeInverse(td));
  float t0 = max(range.x, 0.0);
  float sum = 0.0;
  float n = 0.0;
  for (int i = 0; i < 2048; i++) {
    float t = t0 + (float(i) + 0.5) * u_step;
    if (t >= range.y) break;
    sum += clamp(sampleVolume(to + t * td) * u_valueScale + u_valueBias, 0.0, 1.0);
    n += 1.0;
  }
  FRAG_COLOR = vec4(vec3(n > 0.0 ? sum / n : 0.0), 1.0);
}
)";

class XRayTechnique final : public render::Technique {
 public:
  XRayTechnique(gpu::GlContext& context, const Volume& volume, const layout::Layout& layout)
      : context_(context), volume_(volume), layout_(layout), triangle_(context.ledger()) {}

  std::string name() const override { return "x-ray"; }
  void setTransferFunction(const TransferFunction&) override {}  // shows values, not a TF
  void prepare(const Camera&, const RenderSettings&) override { program(); }

  const gpu::Texture& render(const Camera& camera, const RenderSettings&, int width, int height,
                             double viewAspect) override {
    if (target_.width() != width || target_.height() != height) {
      target_ = gpu::Framebuffer();
      target_ = gpu::Framebuffer::create(context_.ledger(), "x-ray target", width, height);
    }
    target_.bind();
    const gpu::Program& p = program();
    p.use();
    render::setCameraRayUniforms(
        p, camera, viewAspect > 0.0 ? viewAspect : static_cast<double>(width) / height, width,
        height, volume_.extent());
    p.set("u_step", kStepFactor * static_cast<float>(minSpacing(volume_)));
    const layout::ValueMapping m = layout_.rawFromStored();
    const ValueRange w = volume_.window();
    p.set("u_valueScale", static_cast<float>(m.scale / w.width()));
    p.set("u_valueBias", static_cast<float>((m.offset - w.min) / w.width()));
    layout_.bind(p, 0);
    triangle_.draw();
    return target_.color();
  }

  Image readImage() const override {
    Image img(target_.width(), target_.height());
    target_.readRgba8(img.rgba().data());
    img.flipVertically();
    return img;
  }
  std::uint64_t ownTextureBytes() const override { return target_.color().bytes(); }

  static double minSpacing(const Volume& v) {
    return std::min({v.spacing().x, v.spacing().y, v.spacing().z});
  }

 private:
  const gpu::Program& program() {
    if (program_.id() == 0) {
      const gpu::ApiLevel api = context_.caps().api;
      program_ = gpu::Program::build("x-ray(" + layout_.name() + ")",
                                     {gpu::shaderPreamble(api, false, {}),
                                      gpu::embeddedShaderPart("render/fullscreen.vert.glsl")},
                                     {gpu::shaderPreamble(api, true, {}),
                                      gpu::embeddedShaderPart("render/camera_ray.glsl"),
                                      layout_.glsl(),
                                      {"x-ray.frag.glsl", kXRayGlsl}});
    }
    return program_;
  }

  gpu::GlContext& context_;
  const Volume& volume_;
  const layout::Layout& layout_;
  gpu::FullscreenTriangle triangle_;
  gpu::Framebuffer target_;
  gpu::Program program_;
};

// Its registration: no units besides the layout's, its target's bytes.
void registerXRay() {
  render::TechniqueRegistry::global().add(
      {.name = "x-ray",
       .summary = "mean value along the ray",
       .requirements = [](const gpu::DeviceLimits&, glm::ivec3,
                          const render::TechniqueOptions& o) -> render::TechniqueRequirements {
         render::TechniqueRequirements r;
         r.textureUnits = 0;
         r.bytes = static_cast<std::uint64_t>(o.imageSize.x) * o.imageSize.y * 4;
         return r;
       },
       .create = [](const render::TechniqueSetup& s) -> std::unique_ptr<render::Technique> {
         return std::make_unique<XRayTechnique>(s.context, s.volume, *s.layout);
       }});
}

// The same mean on the CPU, in double precision, from the same samples.
Image cpuXRay(const Volume& v, const Camera& camera, int width, int height) {
  Image img(width, height);
  const glm::dvec3 extent = v.extent();
  const double ds = kStepFactor * XRayTechnique::minSpacing(v);
  const ValueRange w = v.window();
  for (int py = 0; py < height; ++py) {
    for (int px = 0; px < width; ++px) {
      const Ray ray = camera.pixelRay(px, py, width, height);
      const glm::dvec3 to = ray.origin / extent + 0.5;
      const glm::dvec3 td = ray.direction / extent;
      double tNear = -std::numeric_limits<double>::infinity();
      double tFar = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        const double t0 = (0.0 - to[a]) / td[a], t1 = (1.0 - to[a]) / td[a];
        tNear = std::max(tNear, std::min(t0, t1));
        tFar = std::min(tFar, std::max(t0, t1));
      }
      double sum = 0.0;
      int n = 0;
      for (double t = std::max(tNear, 0.0) + 0.5 * ds; t < tFar; t += ds, ++n) {
        sum += std::clamp((sampleTrilinear(v, to + t * td) - w.min) / w.width(), 0.0, 1.0);
      }
      const auto grey = static_cast<std::uint8_t>(std::lround(255.0 * (n ? sum / n : 0.0)));
      std::uint8_t* p = img.pixel(px, py);
      p[0] = p[1] = p[2] = grey;
      p[3] = 255;
    }
  }
  return img;
}

// Renders the x-ray as the CLI renders a technique, on `profile`.
void expectXRayMatchesTheCpu(const std::string& profile, const std::string& expectedLayout) {
  const test::BudgetOverride keep(HostBudget::global().limitBytes());
  gpu::DeviceSession device = gpu::openDevice(profile);
  const lod::InCoreVolumeSource source(makeSheppLogan({40, 44, 36}));
  const int width = 72, height = 64;
  {
    render::TechniqueOnVolume t = render::createTechnique("x-ray", *device.context, device.limits,
                                                          source, {.imageSize = {width, height}});
    EXPECT_EQ(t.storageName(), expectedLayout);
    EXPECT_EQ(t.upload.plan.volumeUnits, device.limits.textureUnits);  // nothing reserved
    Camera camera = test::orbitCamera(*t.upload.volume, 35, 20);
    t.technique->prepare(camera, {});
    const Image gpuImage = t.technique->renderImage(camera, {}, width, height);
    const Image cpuImage = cpuXRay(*t.upload.volume, camera, width, height);
    int lit = 0, worst = 0, brightest = 0;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        lit += cpuImage.pixel(x, y)[0] > 4;
        brightest = std::max<int>(brightest, cpuImage.pixel(x, y)[0]);
        worst = std::max(worst, std::abs(gpuImage.pixel(x, y)[0] - cpuImage.pixel(x, y)[0]));
      }
    }
    const double db = psnr(gpuImage, cpuImage);
    std::printf(
        "  [measured] x-ray on %s (%s) vs CPU: %.2f dB, worst pixel %d/255 (%d of %d pixels lit, "
        "brightest %d)\n",
        profile.c_str(), expectedLayout.c_str(), db, worst, lit, width * height, brightest);
    EXPECT_GT(lit, width * height / 10);  // the phantom, not an empty frame
    EXPECT_GT(brightest, 40);
    EXPECT_GE(db, 40.0);
    EXPECT_LE(worst, 8);
  }
  device.context.reset();
  test::gpuContext();  // the shared context current again for later tests
}

}  // namespace

TEST(TechniqueRegistry, ListsTheBuiltInTechniquesRaycastFirst) {
  const std::vector<std::string> names = render::TechniqueRegistry::global().names();
  ASSERT_GE(names.size(), 3u);
  EXPECT_EQ(names[0], "raycast");
  EXPECT_EQ(names[1], "slice3d");
  EXPECT_EQ(names[2], "slice2d");
}

TEST(TechniqueRegistry, UnknownNameIsAnInputErrorListingTheNames) {
  try {
    render::TechniqueRegistry::global().find("splat");
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'splat'"), std::string::npos) << what;
    for (const char* name : {"raycast", "slice3d", "slice2d"}) {
      EXPECT_NE(what.find(name), std::string::npos) << what;
    }
  }
}

TEST(TechniqueRegistry, RequirementsFollowTheDevice) {
  // The ray caster drops its empty-space grid where only two units exist.
  gpu::DeviceLimits limits;
  limits.profile = "tiny";
  limits.textureUnits = 2;
  const render::TechniqueEntry& raycast = render::TechniqueRegistry::global().find("raycast");
  const render::TechniqueRequirements few = raycast.requirements(limits, {64, 64, 64}, {});
  EXPECT_EQ(few.textureUnits, 1);
  EXPECT_NE(few.note.find("empty-space skipping off"), std::string::npos) << few.note;
  limits.textureUnits = 8;
  const render::TechniqueRequirements many = raycast.requirements(limits, {64, 64, 64}, {});
  EXPECT_EQ(many.textureUnits, 2);
  EXPECT_GT(many.bytes, few.bytes);  // + the grid
  EXPECT_TRUE(many.ownStorage.empty());
  // slice2d keeps its own stacks: nothing is planned for it.
  const render::TechniqueRequirements stacks =
      render::TechniqueRegistry::global().find("slice2d").requirements(limits, {64, 64, 64}, {});
  EXPECT_FALSE(stacks.ownStorage.empty());
}

TEST(TechniqueRegistry, LayoutWishesDoNotApplyToATechniqueWithItsOwnStorage) {
  gpu::GlContext& c = test::gpuContext();
  const lod::InCoreVolumeSource source(makeSphere({16, 16, 16}));
  EXPECT_THROW(
      render::createTechnique("slice2d", c, gpu::DeviceLimits::of(c.caps()), source, {}, "mosaic"),
      InputError);
  const render::TechniqueOnVolume t =
      render::createTechnique("slice2d", c, gpu::DeviceLimits::of(c.caps()), source, {});
  EXPECT_EQ(t.upload.layout, nullptr);
  EXPECT_EQ(t.upload.volume.get(), &source.volume());  // its own copy comes from the source
}

// The slicers accumulate in half floats only where the device's limits
// allow them (a profile without float render targets gets RGBA8 on a
// context that has them), so that profile emulation shows the device's
// rounding, not the host's.
TEST(TechniqueRegistry, SliceAccumulationFollowsTheDeviceLimitsNotJustTheContext) {
  gpu::GlContext& c = test::gpuContext();
  const lod::InCoreVolumeSource source(makeSphere({16, 16, 16}));
  gpu::DeviceLimits limits = gpu::DeviceLimits::of(c.caps());
  ASSERT_TRUE(limits.halfFloatRenderTargets) << "llvmpipe renders to RGBA16F";
  const auto formats = [&](const gpu::DeviceLimits& l) {
    const render::TechniqueOnVolume s3 = render::createTechnique("slice3d", c, l, source, {});
    const render::TechniqueOnVolume s2 = render::createTechnique("slice2d", c, l, source, {});
    return dynamic_cast<const render::Slice3DRenderer&>(*s3.technique).accumulationFormat() + " " +
           dynamic_cast<const render::Slice2DRenderer&>(*s2.technique).accumulationFormat();
  };
  EXPECT_EQ(formats(limits), "RGBA16F RGBA16F");
  limits.halfFloatRenderTargets = false;
  EXPECT_EQ(formats(limits), "RGBA8 RGBA8");
}

TEST(TechniqueRegistry, AnXRayTechniqueRegisteredFromATestRendersLikeTheCpu) {
  registerXRay();
  EXPECT_TRUE(render::TechniqueRegistry::global().contains("x-ray"));
  expectXRayMatchesTheCpu("gles3", "texture3d");
  expectXRayMatchesTheCpu("webgl1", "mosaic");
}
