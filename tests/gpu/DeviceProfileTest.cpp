// Device profiles: the built-in table is sane, profiles round-trip through
// JSON, every malformed file is refused naming the file, and effective limits
// are min(profile, caps) on a real headless context.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "support/GpuTestContext.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/GlContext.h"

using namespace tessera;
using namespace tessera::gpu;

namespace {

constexpr std::uint64_t kMiB = 1024ull * 1024;

void writeFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Expects load(file with `text`) to throw InputError whose message names the
// file and contains `fragment`.
void expectRefused(const std::string& text, const std::string& fragment) {
  const test::TempDir tmp;
  const auto path = tmp / "bad.json";
  writeFile(path, text);
  try {
    DeviceProfile::load(path);
    ADD_FAILURE() << "accepted: " << text;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;  // one line for the CLI
  }
}

void expectMinOfProfileAndCaps(const DeviceProfile& p, const DeviceCaps& caps) {
  SCOPED_TRACE(p.name);
  const DeviceLimits l = effectiveLimits(p, caps);
  const DeviceLimits native = DeviceLimits::of(caps);
  EXPECT_EQ(l.profile, p.name);
  EXPECT_EQ(l.api, p.api);
  EXPECT_EQ(l.max2DTextureSize, std::min(p.max2DTextureSize, caps.max2DTextureSize));
  EXPECT_EQ(l.max3DTextureSize,
            p.api == ApiLevel::Gles2 ? 0 : std::min(p.max3DTextureSize, caps.max3DTextureSize));
  EXPECT_EQ(l.textureUnits, std::min(p.textureUnits, caps.maxTextureUnits));
  EXPECT_EQ(l.textureBudget, p.textureBudget);
  EXPECT_EQ(l.hostBudget, p.hostBudget);
  EXPECT_EQ(l.floatRenderTargets, native.floatRenderTargets && p.floatRenderTargets);
  EXPECT_EQ(l.norm16Textures, native.norm16Textures);
  EXPECT_EQ(l.halfFloatTextures, native.halfFloatTextures);
  EXPECT_GT(l.max2DTextureSize, 0);
  EXPECT_GE(l.textureUnits, 1);
}

}  // namespace

TEST(DeviceProfile, BuiltinsAreTheTenNamedProfilesWithNotesAndSaneValues) {
  const auto& all = DeviceProfile::builtins();
  std::set<std::string> names;
  for (const DeviceProfile& p : all) {
    SCOPED_TRACE(p.name);
    EXPECT_FALSE(p.name.empty());
    EXPECT_TRUE(names.insert(p.name).second) << "duplicate name";
    EXPECT_GE(p.note.size(), 20u);
    EXPECT_EQ(p.note.find('\n'), std::string::npos);
    EXPECT_GE(p.max2DTextureSize, 1024);
    EXPECT_LE(p.max2DTextureSize, DeviceProfile::kUnlimited);
    EXPECT_GE(p.textureUnits, 2);
    EXPECT_LE(p.textureUnits, DeviceProfile::kUnlimited);
    if (p.api == ApiLevel::Gles2) {
      EXPECT_EQ(p.max3DTextureSize, 0);
      EXPECT_FALSE(p.floatRenderTargets);
    } else {
      EXPECT_GE(p.max3DTextureSize, 256);  // the ES 3.0 minimum
    }
    // A budget, when there is one, holds at least one max-size RGBA8 2D
    // texture: otherwise the size limit could never be used.
    if (p.textureBudget != 0) {
      const auto side = static_cast<std::uint64_t>(p.max2DTextureSize);
      EXPECT_GE(p.textureBudget, side * side * 4);
    }
  }
  EXPECT_EQ(names,
            (std::set<std::string>{"axim-x51v", "ipad2", "webgl1-desktop-2012", "nexus7",
                                   "shield-k1", "gles2", "webgl1", "gles3", "webgl2", "native"}));
}

TEST(DeviceProfile, PaperDevicesCarryThePapersNumbers) {
  const DeviceProfile axim = DeviceProfile::find("axim-x51v");
  EXPECT_EQ(axim.api, ApiLevel::Gles2);
  EXPECT_EQ(axim.textureBudget, 16 * kMiB);  // Moser & Weiskopf: 16 MB video RAM
  const DeviceProfile ipad = DeviceProfile::find("ipad2");
  EXPECT_EQ(ipad.max2DTextureSize, 2048);
  EXPECT_EQ(ipad.textureUnits, 8);
  // Noguera & Jiménez's 512x512x384 volume: six RGBA 2048² textures.
  EXPECT_GE(ipad.textureBudget, 6 * 2048ull * 2048 * 4);
  const DeviceProfile web = DeviceProfile::find("webgl1-desktop-2012");
  EXPECT_EQ(web.max2DTextureSize, 8192);
  EXPECT_EQ(web.textureUnits, 16);
  EXPECT_EQ(DeviceProfile::find("shield-k1").hostBudget, 469 * kMiB);  // Schultz §5.1
  EXPECT_EQ(DeviceProfile::find("shield-k1").api, ApiLevel::Gles3);
  EXPECT_EQ(DeviceProfile::find("nexus7").api, ApiLevel::Gles3);
  const DeviceProfile native = DeviceProfile::find("native");
  EXPECT_EQ(native.max3DTextureSize, DeviceProfile::kUnlimited);
  EXPECT_EQ(native.textureBudget, 0u);
}

TEST(DeviceProfile, FindsBuiltinsByNameAndFilesByPath) {
  for (const DeviceProfile& p : DeviceProfile::builtins()) {
    EXPECT_EQ(DeviceProfile::find(p.name), p);
  }
  const test::TempDir tmp;
  const auto path = tmp / "phone.json";
  writeFile(path, R"({"name": "phone", "api": "gles3", "max_2d_texture_size": 4096,
                      "max_3d_texture_size": 512, "texture_units": 8,
                      "texture_budget_mb": 300, "host_budget_mb": 0.5})");
  const DeviceProfile p = DeviceProfile::find(path.string());
  EXPECT_EQ(p.name, "phone");
  EXPECT_EQ(p.api, ApiLevel::Gles3);
  EXPECT_EQ(p.max2DTextureSize, 4096);
  EXPECT_EQ(p.max3DTextureSize, 512);
  EXPECT_EQ(p.textureUnits, 8);
  EXPECT_EQ(p.textureBudget, 300 * kMiB);
  EXPECT_EQ(p.hostBudget, kMiB / 2);
  EXPECT_TRUE(p.floatRenderTargets);  // the gles3 default
  EXPECT_EQ(p.note, "");
}

TEST(DeviceProfile, LeftOutFieldsMeanUnlimitedAndFollowTheApiLevel) {
  const DeviceProfile es2 = DeviceProfile::fromJson(R"({"name": "a", "api": "gles2"})", "a");
  EXPECT_EQ(es2.max2DTextureSize, DeviceProfile::kUnlimited);
  EXPECT_EQ(es2.max3DTextureSize, 0);
  EXPECT_EQ(es2.textureUnits, DeviceProfile::kUnlimited);
  EXPECT_EQ(es2.textureBudget, 0u);
  EXPECT_EQ(es2.hostBudget, 0u);
  EXPECT_FALSE(es2.floatRenderTargets);
  const DeviceProfile es3 = DeviceProfile::fromJson(
      R"({"name": "b", "api": "gles3", "max_2d_texture_size": "unlimited"})", "b");
  EXPECT_EQ(es3.max2DTextureSize, DeviceProfile::kUnlimited);
  EXPECT_EQ(es3.max3DTextureSize, DeviceProfile::kUnlimited);
  EXPECT_TRUE(es3.floatRenderTargets);
  // 0 turns 3D textures off on an ES 3 profile (forces the 2D layouts).
  EXPECT_EQ(
      DeviceProfile::fromJson(R"({"name": "c", "api": "gles3", "max_3d_texture_size": 0})", "c")
          .max3DTextureSize,
      0);
}

TEST(DeviceProfile, UnknownNameIsRefusedListingTheBuiltins) {
  for (const std::string& bad : {std::string("ipad3"), std::string("/nonexistent/p.json")}) {
    try {
      DeviceProfile::find(bad);
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(bad), std::string::npos) << message;
      for (const DeviceProfile& p : DeviceProfile::builtins()) {
        EXPECT_NE(message.find(p.name), std::string::npos) << message;
      }
    }
  }
}

TEST(DeviceProfile, EveryBuiltinRoundTripsThroughJson) {
  for (const DeviceProfile& p : DeviceProfile::builtins()) {
    EXPECT_EQ(DeviceProfile::fromJson(p.toJson(), p.name), p) << p.toJson();
  }
  // And through a file, with a budget that is not a whole number of MiB.
  DeviceProfile odd = DeviceProfile::find("ipad2");
  odd.name = "odd";
  odd.textureBudget = 3 * kMiB + 12345;
  const test::TempDir tmp;
  writeFile(tmp / "odd.json", odd.toJson());
  EXPECT_EQ(DeviceProfile::load(tmp / "odd.json"), odd);
}

TEST(DeviceProfile, MalformedFilesAreRefusedNamingTheFile) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"name": "x", "api": "gles3",)", "malformed JSON"},
      {R"({"name": "x", "api": "gles3", "max_texture_size": 4096})", "max_texture_size"},
      {R"({"api": "gles3"})", "missing \"name\""},
      {R"({"name": "x"})", "missing \"api\""},
      {R"({"name": "", "api": "gles3"})", "\"name\""},
      {R"({"name": 7, "api": "gles3"})", "\"name\""},
      {R"({"name": "x", "api": "gles4"})", "gles4"},
      {R"({"name": "x", "api": "gles3", "max_2d_texture_size": 0})", "max_2d_texture_size"},
      {R"({"name": "x", "api": "gles3", "max_2d_texture_size": -2048})", "max_2d_texture_size"},
      {R"({"name": "x", "api": "gles3", "max_2d_texture_size": 2048.5})", "max_2d_texture_size"},
      {R"({"name": "x", "api": "gles3", "max_2d_texture_size": "big"})", "max_2d_texture_size"},
      {R"({"name": "x", "api": "gles3", "max_2d_texture_size": 99999999999})",
       "max_2d_texture_size"},
      {R"({"name": "x", "api": "gles3", "max_3d_texture_size": -1})", "max_3d_texture_size"},
      {R"({"name": "x", "api": "gles2", "max_3d_texture_size": 256})", "max_3d_texture_size"},
      {R"({"name": "x", "api": "gles3", "texture_units": 0})", "texture_units"},
      {R"({"name": "x", "api": "gles3", "texture_budget_mb": -1})", "texture_budget_mb"},
      {R"({"name": "x", "api": "gles3", "host_budget_mb": -0.5})", "host_budget_mb"},
      {R"({"name": "x", "api": "gles3", "host_budget_mb": "lots"})", "host_budget_mb"},
      {R"({"name": "x", "api": "gles3", "host_budget_mb": 1e300})", "host_budget_mb"},
      {R"({"name": "x", "api": "gles2", "float_render_targets": true})", "float_render_targets"},
      {R"({"name": "x", "api": "gles3", "float_render_targets": 1})", "float_render_targets"},
      {R"({"name": "x", "api": "gles3", "note": "two\nlines"})", "note"},
      {R"(["name", "x"])", "object"},
      {"", "malformed JSON"},
      // Found by fuzz_device_profile: a number no double holds is out_of_range,
      // not parse_error, in nlohmann-json.
      {R"({"name": "x", "api": "gles3", "texture_units": 4E444444})", "malformed JSON"},
  };
  for (const auto& [text, fragment] : cases) {
    SCOPED_TRACE(text);
    expectRefused(text, fragment);
  }
}

// Inputs fuzz_device_profile once crashed on (tests/data/bad/fuzz-regressions).
TEST(DeviceProfile, FuzzRegressionsAreRefusedNamingTheFile) {
  const auto dir =
      std::filesystem::path(TESSERA_TEST_DATA_DIR) / "bad" / "fuzz-regressions" / "device_profile";
  int cases = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    SCOPED_TRACE(entry.path().string());
    ++cases;
    try {
      DeviceProfile::load(entry.path());
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(entry.path().string()), std::string::npos) << e.what();
    }
  }
  EXPECT_GE(cases, 1);
}

TEST(DeviceProfile, MissingFileIsRefusedNamingIt) {
  try {
    DeviceProfile::load("/nonexistent/profile.json");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/profile.json"), std::string::npos);
  }
}

TEST(DeviceProfile, EffectiveLimitsAreMinOfProfileAndEs3Caps) {
  const DeviceCaps& caps = test::gpuContext().caps();
  ASSERT_EQ(caps.api, ApiLevel::Gles3);
  int checked = 0;
  for (const DeviceProfile& p : DeviceProfile::builtins()) {
    if (p.api != ApiLevel::Gles3) continue;
    expectMinOfProfileAndCaps(p, caps);
    ++checked;
  }
  EXPECT_EQ(checked, 5);
  // native leaves the context exactly as it is.
  const DeviceLimits native = effectiveLimits(DeviceProfile::find("native"), caps);
  const DeviceLimits of = DeviceLimits::of(caps);
  EXPECT_EQ(native.max2DTextureSize, of.max2DTextureSize);
  EXPECT_EQ(native.max3DTextureSize, of.max3DTextureSize);
  EXPECT_EQ(native.textureUnits, of.textureUnits);
  EXPECT_EQ(native.floatRenderTargets, of.floatRenderTargets);
  // A profile below the context's limits actually lowers them.
  const DeviceLimits g3 = effectiveLimits(DeviceProfile::find("gles3"), caps);
  EXPECT_EQ(g3.max2DTextureSize, std::min(2048, caps.max2DTextureSize));
  EXPECT_EQ(g3.max3DTextureSize, std::min(256, caps.max3DTextureSize));
  EXPECT_FALSE(g3.floatRenderTargets);
}

TEST(DeviceProfile, EffectiveLimitsAreMinOfProfileAndEs2Caps) {
  GlContext::Options options;
  options.api = ApiLevel::Gles2;
  int checked = 0;
  {
    const auto es2 = GlContext::createHeadless(options);
    ASSERT_EQ(es2->caps().api, ApiLevel::Gles2);
    for (const DeviceProfile& p : DeviceProfile::builtins()) {
      if (p.api != ApiLevel::Gles2) continue;
      expectMinOfProfileAndCaps(p, es2->caps());
      ++checked;
    }
    // A gles3 profile cannot run on an ES 2 context.
    EXPECT_THROW(effectiveLimits(DeviceProfile::find("gles3"), es2->caps()), GpuError);
  }
  EXPECT_EQ(checked, 5);
  test::gpuContext();  // make the shared ES 3 context current again for the other tests
}

TEST(DeviceProfile, Gles2ProfileOnEs3ContextIsAnError) {
  const DeviceCaps& caps = test::gpuContext().caps();
  for (const DeviceProfile& p : DeviceProfile::builtins()) {
    if (p.api == ApiLevel::Gles2) {
      EXPECT_THROW(effectiveLimits(p, caps), GpuError) << p.name;
    }
  }
}
