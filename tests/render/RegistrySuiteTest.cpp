// Every registered technique on every registered layout, at both API levels
// (the gles2 and gles3 device profiles), in four cases (composite, MIP,
// shaded, clipped), each frame against its CPU twin through the path the
// CLI takes (session::runRender with the reference: the layout's own
// reference field, the technique's sampling twin, a streamed layout refined
// first). The cases are computed from the registries when gtest instantiates
// the suite, after every static initialiser ran: an entry registered anywhere
// in this binary (tests/render/RegistryExtensionTest.cpp registers two) is
// image-tested here with no test edited. What may not run is decided from
// the entries' properties and skipped with the reason. A layout that streams
// bricks runs twice: on the in-core volume (the reference reads its voxels)
// and on the same volume as a streamed pyramid, held nowhere whole (the
// reference reads the pyramid level the refined frame shows, as
// `tessera render STORE --layout bricks --reference` does). RegistryWindows
// adds narrow windows (1 % and 10 % of the range) on streamed u8, u16, i16
// and f32 pyramids for the ray casters on the layouts that stream.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "support/TestSupport.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/HostBudget.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/io/Procedural.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/lod/MultiresVolumeSource.h"
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/RenderRun.h"

using namespace tessera;

namespace {

enum class Case { Composite, Mip, Shaded, Clipped };

const char* caseName(Case c) {
  switch (c) {
    case Case::Composite:
      return "composite";
    case Case::Mip:
      return "mip";
    case Case::Shaded:
      return "shaded";
    case Case::Clipped:
      return "clipped";
  }
  return "?";
}

constexpr Case kCases[] = {Case::Composite, Case::Mip, Case::Shaded, Case::Clipped};
// The device profiles of the two API levels (gpu/DeviceProfile.cpp): the
// spec's minimum maxima, no float render targets.
const char* const kProfiles[] = {"gles2", "gles3"};
// Small frames of another shape than square (an aspect mistake shows).
constexpr int kWidth = 88;
constexpr int kHeight = 72;

struct Combo {
  std::string technique;
  std::string layout;  // "auto" for a technique with its own storage
  std::string profile;
  Case which = Case::Composite;
  bool streamed = false;  // the volume as a pyramid read box by box (MultiresVolumeSource)
};

// gtest prints it in messages and in the test list (ctest shows that list).
void PrintTo(const Combo& c, std::ostream* os) {
  *os << c.technique << " on " << c.layout << (c.streamed ? " (streamed)" : "") << ", " << c.profile
      << ", " << caseName(c.which);
}

// A technique with its own storage plans no layout; asked with generic
// limits and a small volume (what it stores does not depend on either).
bool ownsStorage(const render::TechniqueEntry& t) {
  return !t.requirements(gpu::DeviceLimits{}, {32, 32, 32}, render::TechniqueOptions{})
              .ownStorage.empty();
}

// Evaluated when gtest instantiates the suite (in InitGoogleTest), not
// before main: registrations from any file's static initialiser are in.
std::vector<Combo> combos() {
  std::vector<Combo> all;
  for (const render::TechniqueEntry& t : render::TechniqueRegistry::global().entries()) {
    std::vector<std::pair<std::string, bool>> layouts;  // name, streamed
    if (ownsStorage(t)) {
      layouts.emplace_back("auto", false);
    } else {
      for (const layout::LayoutEntry& l : layout::LayoutRegistry::global().entries()) {
        layouts.emplace_back(l.name, false);
        if (l.streamsBricks) layouts.emplace_back(l.name, true);
      }
    }
    for (const char* profile : kProfiles) {
      for (const auto& [l, streamed] : layouts) {
        for (Case c : kCases) all.push_back({t.name, l, profile, c, streamed});
      }
    }
  }
  return all;
}

std::string identifier(const std::string& s) {
  std::string out;
  for (char ch : s) out += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  return out;
}

std::string comboName(const testing::TestParamInfo<Combo>& info) {
  const Combo& c = info.param;
  return identifier(c.technique) + "_" +
         (c.layout == "auto" ? "ownStorage" : identifier(c.layout)) +
         (c.streamed ? "_streamed" : "") + "_" + c.profile + "_" + caseName(c.which);
}

// Two planes and a crop box that cut into the volume (ClippingTest's).
Clipping clipping() {
  Clipping c;
  c.planes.push_back({{0.0, 1.0, 0.0}, 2.0});
  c.planes.push_back({{-1.0, 0.0, -1.0}, 6.0});
  c.cropMin = {0.1, 0.0, 0.15};
  c.cropMax = {0.85, 1.0, 1.0};
  return c;
}

// The case's volume and settings. Slicing cannot stop early, so early ray
// termination is off for every technique (the twin is told the same);
// sampling is the front ends' default (adaptive steps), which runRender
// drops for a technique that does not honour it.
RenderSettings settingsFor(Case c) {
  RenderSettings s = defaultRenderSettings();
  s.stepVoxels = 0.5;
  s.ertThreshold = 1.0;
  if (c == Case::Mip) s.mode = RenderMode::Mip;
  if (c == Case::Shaded) s.shading.enabled = true;
  if (c == Case::Clipped) s.clipping = clipping();
  return s;
}

// The volume weighted by ramps along x and z, so that no mirror image of it
// (a layout or technique that flips an axis) comes close to it: the sphere
// and the phantom are nearly symmetric, and a layout sampling the phantom
// mirrored in z still measured 48 dB against the reference.
Volume lopsided(Volume v) {
  const glm::ivec3 d = v.dims();
  std::size_t i = 0;
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x, ++i) {
        const double wz = 0.3 + 0.7 * (z + 0.5) / d.z;
        const double wx = 0.6 + 0.4 * (x + 0.5) / d.x;
        v.setValueAtIndex(i, v.valueAtIndex(i) * wz * wx);
      }
    }
  }
  v.invalidateRange();
  return v;
}

// Odd dims, so that mosaic tiles and packed channels do not line up with
// powers of two; a sphere for the shaded and clipped cases (smooth normals,
// an inside to cut into), the Shepp-Logan phantom for the others; both
// lopsided.
Volume volumeFor(Case c) {
  if (c == Case::Shaded || c == Case::Clipped) return lopsided(makeSphere({37, 41, 29}));
  return lopsided(makeSheppLogan({37, 41, 29}));
}

// The bars, by what the technique and the layout do rather than their names.
// A technique that scissors to the volume casts a ray per pixel through the
// box (its rays miss outside it), as its twin does: the image tests hold ray
// casting to 40 dB on every layout and case (LayoutRenderTest, ShadingTest,
// ClippingTest); measured here 59.6-71.6 dB on the layouts that hold the
// voxel grid. The others draw planes that sample other positions than the twin's
// rays and, on these profiles (no float render targets), accumulate in
// RGBA8: Slice3DTest and Slice2DTest hold them to 30 dB (measured here
// 32.3-50.5 dB, slice2d's MIP the lowest).
// Lit frames on a layout that reconstructs another field than the voxels'
// (fcc's box spline, evaluated on the GPU, differentiated by central
// differences of that evaluation) measured 41.0-42.1 dB against the
// reference's box spline here, but 37.2 dB on the sphere without the ramps:
// those are held to 35 dB.
struct Bar {
  double psnrDb;
  double ssim;
};

Bar barFor(const render::TechniqueEntry& t, const layout::LayoutEntry* l, Case c) {
  Bar bar = t.scissorsToVolume ? Bar{40.0, 0.97} : Bar{30.0, 0.95};
  if (c == Case::Shaded && l != nullptr && !l->holdsVoxelGrid) {
    bar.psnrDb = std::min(bar.psnrDb, 35.0);
  }
  return bar;
}

class RegistrySuite : public testing::TestWithParam<Combo> {};

TEST_P(RegistrySuite, MatchesItsCpuTwin) {
  const Combo& combo = GetParam();
  const render::TechniqueEntry& technique =
      render::TechniqueRegistry::global().find(combo.technique);
  const test::BudgetOverride keep(HostBudget::global().limitBytes());
  gpu::DeviceSession device = gpu::openDevice(combo.profile);
  const lod::InCoreVolumeSource inCore(volumeFor(combo.which));
  const lod::MultiresVolumeSource pyramid(
      std::make_shared<lod::InCoreMultiresSource>(inCore.level(glm::ivec3(1))));
  const lod::VolumeSource& source =
      combo.streamed ? static_cast<const lod::VolumeSource&>(pyramid) : inCore;
  if (combo.layout != "auto") {
    const layout::LayoutEntry& entry = layout::LayoutRegistry::global().find(combo.layout);
    if (!entry.runsOn(device.limits)) {
      GTEST_SKIP() << combo.layout << " does not run on the " << combo.profile << " profile ("
                   << (entry.needsText.empty()
                           ? (entry.needs3DTextures ? "needs 3D textures" : "needs OpenGL ES 3")
                           : "needs " + entry.needsText)
                   << ")";
    }
    // What the planner would refuse on this profile (a volume too large for
    // its textures, too few units): the entry's own plan says why.
    const int units =
        device.limits.textureUnits -
        technique
            .requirements(device.limits, source.shape().dims(), {.imageSize = {kWidth, kHeight}})
            .textureUnits;
    const layout::LayoutPlan plan = entry.plan(source.shape(), device.limits, units);
    if (!plan.fits) {
      GTEST_SKIP() << combo.layout << " does not fit on the " << combo.profile
                   << " profile: " << plan.reason;
    }
  }
  session::RenderRequest request;
  request.settings.technique = combo.technique;
  request.settings.layout = combo.layout;
  request.settings.tf = test::visibleTf();
  request.settings.render = settingsFor(combo.which);
  // Lit samples take the gradient through the layout's seam: with "auto" a
  // technique may light (and, with 8-bit voxels, read values) from a gradient
  // texture made of the voxels, and never sample the layout (a layout
  // mirrored in z passed the shaded case at 62 dB that way). The
  // precomputed gradient is ShadingTest's.
  request.settings.gradient = "on-the-fly";
  request.settings.camera.azimuthDeg = 35;
  request.settings.camera.elevationDeg = 25;
  request.width = kWidth;
  request.height = kHeight;
  request.reference = true;
  const session::RenderResult r = session::runRender(device, source, request);
  // Its own context goes; the other tests make the shared one current again
  // (test::gpuContext()), so none is created here for nothing.
  device.context.reset();

  ASSERT_TRUE(r.psnrDb && r.ssim);
  if (combo.layout != "auto") {
    EXPECT_EQ(r.layout, combo.layout);
  }
  // A streamed layout's reference reads the level the refined frame shows:
  // at these sizes every cell shows level 0.
  if (r.bricks) {
    ASSERT_TRUE(r.referenceLevel);
    EXPECT_EQ(*r.referenceLevel, 0) << r.referenceLevelNote;
    EXPECT_FALSE(r.referenceLevelMixed) << r.referenceLevelNote;
  }
  ASSERT_TRUE(r.referenceImage);
  // The reference shows the volume (not an empty frame that any empty
  // frame would match): the smallest, the clipped sphere, lights a few
  // percent of the pixels.
  int lit = 0;
  const Image& ref = *r.referenceImage;
  for (int y = 0; y < ref.height(); ++y) {
    for (int x = 0; x < ref.width(); ++x) {
      const std::uint8_t* p = ref.pixel(x, y);
      lit += std::max({p[0], p[1], p[2]}) > 8;
    }
  }
  EXPECT_GT(lit, kWidth * kHeight / 25);
  const Bar bar = barFor(
      technique,
      combo.layout == "auto" ? nullptr : &layout::LayoutRegistry::global().find(combo.layout),
      combo.which);
  std::printf("  [measured] %s on %s%s, %s, %s: %.2f dB, SSIM %.4f (bar %.0f dB, %.2f)%s%s\n",
              combo.technique.c_str(), r.layout.c_str(), combo.streamed ? " (streamed)" : "",
              combo.profile.c_str(), caseName(combo.which), *r.psnrDb, *r.ssim, bar.psnrDb,
              bar.ssim, r.adaptive ? ", adaptive steps" : "", r.bricks ? ", bricks refined" : "");
  EXPECT_GE(*r.psnrDb, bar.psnrDb);
  EXPECT_GE(*r.ssim, bar.ssim);
}

INSTANTIATE_TEST_SUITE_P(Registries, RegistrySuite, testing::ValuesIn(combos()), comboName);

}  // namespace

namespace {

// Narrow windows on streamed volumes of each scalar type (issue 31 item 1:
// the bricks keep the data's precision and apply the window as in-core
// does): every ray-casting technique on every layout that streams bricks,
// at both API levels, the phantom as a u8, u16, i16 and f32 pyramid read
// box by box, under windows of 1 % and 10 % of its range centred in its
// soft tissue, against the reference of the levels the refined frame shows
// through the path the CLI takes. Composite only (the window is the same
// in every mode); small frames, so each case takes well under a second.
struct WindowCombo {
  std::string technique;
  std::string layout;
  std::string profile;
  ScalarType type = ScalarType::U8;
  double fraction = 0.01;
};

void PrintTo(const WindowCombo& c, std::ostream* os) {
  *os << c.technique << " on " << c.layout << " (streamed), " << c.profile << ", "
      << scalarTypeName(c.type) << ", window " << 100.0 * c.fraction << "%";
}

std::vector<WindowCombo> windowCombos() {
  std::vector<WindowCombo> all;
  for (const render::TechniqueEntry& t : render::TechniqueRegistry::global().entries()) {
    if (ownsStorage(t) || !t.scissorsToVolume) continue;
    for (const layout::LayoutEntry& l : layout::LayoutRegistry::global().entries()) {
      if (!l.streamsBricks) continue;
      for (const char* profile : kProfiles) {
        for (ScalarType type :
             {ScalarType::U8, ScalarType::U16, ScalarType::I16, ScalarType::F32}) {
          for (double fraction : {0.01, 0.1})
            all.push_back({t.name, l.name, profile, type, fraction});
        }
      }
    }
  }
  return all;
}

std::string windowComboName(const testing::TestParamInfo<WindowCombo>& info) {
  const WindowCombo& c = info.param;
  return identifier(c.technique) + "_" + identifier(c.layout) + "_" + c.profile + "_" +
         std::string(scalarTypeName(c.type)) + "_window" +
         std::to_string(std::lround(100.0 * c.fraction)) + "pct";
}

// Raw value of the u8 phantom's value f in `type`: u16 and i16 (partly
// negative) well past 8 bits, f32 below 1 (tests/app/StreamedReferenceTest's
// mapping).
double rawOf(ScalarType type, double f) {
  if (type == ScalarType::U16) return 37.0 * f + 200.0;
  if (type == ScalarType::I16) return 23.0 * f - 1200.0;
  if (type == ScalarType::F32) return f / 255.0 * 3.0 - 0.8;
  return f;
}

// The composite case's phantom in `type`, windowed to `fraction` of its
// range around the soft tissue (u8 30: the brain under the ramps, 9..51).
std::shared_ptr<const Volume> windowedPhantom(ScalarType type, double fraction) {
  const Volume base = volumeFor(Case::Composite);
  auto v = std::make_shared<Volume>(Volume::allocate(base.dims(), type, "phantom"));
  for (std::size_t i = 0; i < base.voxelCount(); ++i) {
    v->setValueAtIndex(i, rawOf(type, base.valueAtIndex(i)));
  }
  v->invalidateRange();
  const ValueRange range = v->valueRange();
  const double width = fraction * (range.max - range.min);
  const double centre = rawOf(type, 30.0);
  v->setWindow({centre - width / 2.0, centre + width / 2.0});
  return v;
}

class RegistryWindows : public testing::TestWithParam<WindowCombo> {};

TEST_P(RegistryWindows, StreamedNarrowWindowMatchesItsCpuTwin) {
  const WindowCombo& combo = GetParam();
  const test::BudgetOverride keep(HostBudget::global().limitBytes());
  gpu::DeviceSession device = gpu::openDevice(combo.profile);
  const layout::LayoutEntry& entry = layout::LayoutRegistry::global().find(combo.layout);
  if (!entry.runsOn(device.limits)) {
    GTEST_SKIP() << combo.layout << " does not run on the " << combo.profile << " profile";
  }
  const lod::MultiresVolumeSource pyramid(
      std::make_shared<lod::InCoreMultiresSource>(windowedPhantom(combo.type, combo.fraction)));
  session::RenderRequest request;
  request.settings.technique = combo.technique;
  request.settings.layout = combo.layout;
  request.settings.tf = test::visibleTf();
  request.settings.render = settingsFor(Case::Composite);
  request.settings.camera.azimuthDeg = 35;
  request.settings.camera.elevationDeg = 25;
  request.width = kWidth;
  request.height = kHeight;
  request.reference = true;
  const session::RenderResult r = session::runRender(device, pyramid, request);
  device.context.reset();

  ASSERT_TRUE(r.psnrDb && r.ssim && r.referenceImage && r.bricks);
  EXPECT_EQ(r.layout, combo.layout);
  EXPECT_TRUE(r.bricks->complete);
  // The window shows the tissue (not an empty frame): a narrow window lights
  // what lies above it.
  int lit = 0;
  const Image& ref = *r.referenceImage;
  for (int y = 0; y < ref.height(); ++y) {
    for (int x = 0; x < ref.width(); ++x) {
      const std::uint8_t* p = ref.pixel(x, y);
      lit += std::max({p[0], p[1], p[2]}) > 8;
    }
  }
  EXPECT_GT(lit, kWidth * kHeight / 10);
  std::printf(
      "  [measured] %s on %s (streamed), %s, %s window %g%%: %.2f dB, SSIM %.4f "
      "(level %d%s)\n",
      combo.technique.c_str(), r.layout.c_str(), combo.profile.c_str(),
      std::string(scalarTypeName(combo.type)).c_str(), 100.0 * combo.fraction, *r.psnrDb, *r.ssim,
      r.referenceLevel.value_or(-1), r.referenceLevelMixed ? ", mixed" : "");
  EXPECT_GE(*r.psnrDb, 45.0);
  EXPECT_GE(*r.ssim, 0.98);
}

INSTANTIATE_TEST_SUITE_P(Registries, RegistryWindows, testing::ValuesIn(windowCombos()),
                         windowComboName);

}  // namespace
