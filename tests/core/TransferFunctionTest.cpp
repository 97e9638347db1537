#include "support/ExpectError.h"
#include "support/TestSupport.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/TransferFunction.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "tessera/core/Error.h"

namespace tessera {
namespace {

using test::BudgetOverride;
using test::TempDir;

namespace fs = std::filesystem;

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

using test::inputErrorMessage;

void expectSameTf(const TransferFunction& a, const TransferFunction& b) {
  EXPECT_EQ(a.name, b.name);
  // Exact comparisons: the JSON round trip must not lose a single bit.
  EXPECT_EQ(a.opacityUnitLength, b.opacityUnitLength);
  ASSERT_EQ(a.colors.size(), b.colors.size());
  for (std::size_t i = 0; i < a.colors.size(); ++i) {
    EXPECT_EQ(a.colors[i].x, b.colors[i].x) << "color " << i;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(a.colors[i].rgb[c], b.colors[i].rgb[c]) << "color " << i;
  }
  ASSERT_EQ(a.opacities.size(), b.opacities.size());
  for (std::size_t i = 0; i < a.opacities.size(); ++i) {
    EXPECT_EQ(a.opacities[i].x, b.opacities[i].x) << "opacity " << i;
    EXPECT_EQ(a.opacities[i].alpha, b.opacities[i].alpha) << "opacity " << i;
  }
}

TEST(TransferFunction, InterpolatesLinearlyBetweenControlPoints) {
  const TransferFunction tf = test::tfFromPoints({{0.2, {1.0, 0.0, 0.0}}, {0.6, {0.0, 0.0, 1.0}}},
                                                 {{0.0, 0.0}, {0.5, 0.4}, {1.0, 0.1}});

  EXPECT_EQ(tf.color(0.2), glm::dvec3(1.0, 0.0, 0.0));
  EXPECT_EQ(tf.color(0.6), glm::dvec3(0.0, 0.0, 1.0));
  const glm::dvec3 mid = tf.color(0.4);
  EXPECT_NEAR(mid.r, 0.5, 1e-15);
  EXPECT_NEAR(mid.g, 0.0, 1e-15);
  EXPECT_NEAR(mid.b, 0.5, 1e-15);
  const glm::dvec3 q = tf.color(0.5);
  EXPECT_NEAR(q.r, 0.25, 1e-15);
  EXPECT_NEAR(q.b, 0.75, 1e-15);

  EXPECT_DOUBLE_EQ(tf.opacity(0.5), 0.4);
  EXPECT_NEAR(tf.opacity(0.25), 0.2, 1e-15);
  EXPECT_NEAR(tf.opacity(0.75), 0.25, 1e-15);
  const glm::dvec4 e = tf.evaluate(0.1);
  EXPECT_EQ(e.r, 1.0);  // left of the first colour point
  EXPECT_EQ(e.b, 0.0);
  EXPECT_NEAR(e.a, 0.08, 1e-15);
}

TEST(TransferFunction, HoldsEndValuesOutsideTheControlPoints) {
  const TransferFunction tf = test::tfFromPoints({{0.3, {0.1, 0.2, 0.3}}, {0.7, {0.9, 0.8, 0.7}}},
                                                 {{0.3, 0.05}, {0.7, 0.6}});
  for (double x : {0.0, 0.1, 0.3, -2.0, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_EQ(tf.color(x), glm::dvec3(0.1, 0.2, 0.3)) << x;
    EXPECT_EQ(tf.opacity(x), 0.05) << x;
  }
  for (double x : {0.7, 0.95, 1.0, 5.0}) {
    EXPECT_EQ(tf.color(x), glm::dvec3(0.9, 0.8, 0.7)) << x;
    EXPECT_EQ(tf.opacity(x), 0.6) << x;
  }
}

TEST(TransferFunction, EmptyListsAreBlackAndTransparent) {
  const TransferFunction tf;
  EXPECT_EQ(tf.evaluate(0.5), glm::dvec4(0.0));
  EXPECT_EQ(tf.correctedOpacity(0.5, 1.0, 1.0), 0.0);
}

TEST(TransferFunction, AddKeepsPointsSortedAndEqualXMakesAStep) {
  TransferFunction tf;
  tf.addOpacity(1.0, 1.0);
  tf.addOpacity(0.0, 0.0);
  tf.addOpacity(0.5, 0.0);
  tf.addOpacity(0.5, 1.0);  // after the first 0.5: the jump up happens at 0.5
  ASSERT_EQ(tf.opacities.size(), 4u);
  EXPECT_EQ(tf.opacities[0].x, 0.0);
  EXPECT_EQ(tf.opacities[1].alpha, 0.0);
  EXPECT_EQ(tf.opacities[2].alpha, 1.0);
  EXPECT_EQ(tf.opacities[3].x, 1.0);
  EXPECT_EQ(tf.opacity(0.25), 0.0);
  EXPECT_EQ(tf.opacity(0.4999), 0.0);
  EXPECT_EQ(tf.opacity(0.5), 1.0);
  EXPECT_EQ(tf.opacity(0.75), 1.0);

  // Steps at the ends follow the same rule: the later point holds from its x on.
  TransferFunction ends;
  ends.addOpacity(0.0, 0.2);
  ends.addOpacity(0.0, 0.6);
  ends.addOpacity(1.0, 0.1);
  ends.addOpacity(1.0, 0.9);
  EXPECT_EQ(ends.opacity(-1.0), 0.2);  // left of everything: the first point
  EXPECT_EQ(ends.opacity(0.0), 0.6);
  EXPECT_NEAR(ends.opacity(0.5), 0.35, 1e-15);
  EXPECT_EQ(ends.opacity(1.0), 0.9);
}

TEST(TransferFunction, AddRejectsValuesOutsideTheUnitInterval) {
  TransferFunction tf;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(tf.addColor(1.5, {0.0, 0.0, 0.0}), InputError);
  EXPECT_THROW(tf.addColor(0.5, {0.0, 1.01, 0.0}), InputError);
  EXPECT_THROW(tf.addColor(nan, {0.0, 0.0, 0.0}), InputError);
  EXPECT_THROW(tf.addOpacity(-0.1, 0.5), InputError);
  EXPECT_THROW(tf.addOpacity(0.5, -0.01), InputError);
  EXPECT_THROW(tf.addOpacity(0.5, nan), InputError);
  EXPECT_TRUE(tf.colors.empty());
  EXPECT_TRUE(tf.opacities.empty());
}

TEST(TransferFunction, CorrectedOpacityFollowsTheDistanceFormula) {
  TransferFunction tf;
  tf.opacityUnitLength = 2.0;
  tf.addOpacity(0.0, 0.3);
  tf.addOpacity(1.0, 0.3);
  for (double ds : {0.1, 0.25, 0.5, 1.0, 2.0, 3.7}) {
    // a = 1 - (1 - a0)^(ds / unit), computed directly.
    EXPECT_NEAR(tf.correctedOpacity(0.5, ds, 1.0), 1.0 - std::pow(0.7, ds / 2.0), 1e-15) << ds;
    EXPECT_NEAR(tf.correctedOpacity(0.5, ds, 2.0), 1.0 - std::pow(0.4, ds / 2.0), 1e-15) << ds;
    // The scaled opacity 0.3 * 5 is clamped to 1: fully opaque at any ds > 0.
    EXPECT_EQ(tf.correctedOpacity(0.5, ds, 5.0), 1.0) << ds;
    // Two samples of ds/2 composite to exactly the opacity of one sample of ds.
    const double half = tf.correctedOpacity(0.5, ds / 2.0, 1.0);
    EXPECT_NEAR(1.0 - (1.0 - half) * (1.0 - half), tf.correctedOpacity(0.5, ds, 1.0), 1e-15);
  }
  // ds equal to the unit length leaves the opacity unchanged; ds 0 makes it 0.
  EXPECT_NEAR(tf.correctedOpacity(0.5, 2.0, 1.0), 0.3, 1e-15);
  EXPECT_EQ(tf.correctedOpacity(0.5, 0.0, 1.0), 0.0);
  EXPECT_EQ(tf.correctedOpacity(0.5, 1.0, 0.0), 0.0);
}

TEST(TransferFunction, BakeMapsEntryIToXEqualsIOverEntriesMinusOne) {
  TransferFunction tf;
  tf.opacityUnitLength = 0.5;
  tf.addColor(0.0, {0.0, 1.0, 0.25});
  tf.addColor(1.0, {1.0, 0.0, 0.75});
  tf.addOpacity(0.0, 0.0);
  tf.addOpacity(0.3, 0.0);
  tf.addOpacity(1.0, 0.7);
  const double ds = 0.3;
  const double scale = 1.2;
  for (int entries : {256, 4096}) {
    const std::vector<float> lut = tf.bake(entries, ds, scale);
    ASSERT_EQ(lut.size(), static_cast<std::size_t>(entries) * 4);
    for (int i = 0; i < entries; ++i) {
      const double x = static_cast<double>(i) / (entries - 1);
      const float* e = &lut[static_cast<std::size_t>(i) * 4];
      ASSERT_EQ(e[0], static_cast<float>(x)) << entries << " entry " << i;
      ASSERT_EQ(e[1], static_cast<float>(1.0 - x)) << entries << " entry " << i;
      ASSERT_EQ(e[2], static_cast<float>(tf.color(x).b)) << entries << " entry " << i;
      ASSERT_EQ(e[3], static_cast<float>(tf.correctedOpacity(x, ds, scale)))
          << entries << " entry " << i;
    }
    // End entries sit exactly on the end control points.
    EXPECT_EQ(lut[0], 0.0f);
    EXPECT_EQ(lut[3], 0.0f);
    const float* last = &lut[static_cast<std::size_t>(entries - 1) * 4];
    EXPECT_EQ(last[0], 1.0f);
    EXPECT_FLOAT_EQ(last[3], static_cast<float>(1.0 - std::pow(1.0 - 0.84, ds / 0.5)));
  }
}

TEST(TransferFunction, BakeRejectsUnsupportedSizesAndBadParameters) {
  const TransferFunction tf = TransferFunction::preset("grey");
  for (int entries : {-1, 0, 1, 255, 257, 512, 1024, 4095}) {
    const std::string msg = inputErrorMessage([&] { tf.bake(entries, 1.0, 1.0); });
    EXPECT_NE(msg.find(std::to_string(entries)), std::string::npos) << msg;
  }
  EXPECT_THROW(tf.bake(256, -1.0, 1.0), InputError);
  EXPECT_THROW(tf.bake(256, std::numeric_limits<double>::quiet_NaN(), 1.0), InputError);
  EXPECT_THROW(tf.bake(256, 1.0, -0.5), InputError);
}

TEST(TransferFunction, JsonRoundTripPreservesEveryPointExactly) {
  TransferFunction tf;
  tf.name = "awkward \"doubles\"";
  tf.opacityUnitLength = 0.123456789012345678;
  tf.addColor(0.1, {1.0 / 3.0, 0.1 + 0.2, std::nextafter(1.0, 0.0)});
  tf.addColor(2.0 / 3.0, {5e-324, 0.7000000000000001, 1.0});
  tf.addColor(2.0 / 3.0, {0.0, 0.5, 0.25});  // step: order of equal x must survive
  tf.addOpacity(0.0, 1e-17);
  tf.addOpacity(0.333333333333333314829616256247, 0.999999999999999889);
  tf.addOpacity(1.0, 0.05);

  const TransferFunction back = TransferFunction::fromJson(tf.toJson());
  expectSameTf(tf, back);

  TempDir dir;
  const fs::path path = dir.file("awkward.json");
  tf.save(path);
  expectSameTf(tf, TransferFunction::load(path));
}

TEST(TransferFunction, EveryPresetLoadsAndRoundTrips) {
  const std::vector<std::string> names = TransferFunction::presetNames();
  EXPECT_EQ(names, (std::vector<std::string>{"grey", "mr-default", "ct-bone", "ct-muscle", "bench",
                                             "ct-bone-hu", "ct-soft-tissue", "ct-lung", "ct-angio",
                                             "mr-percentile"}));
  TempDir dir;
  for (const std::string& name : names) {
    const TransferFunction tf = TransferFunction::preset(name);
    EXPECT_EQ(tf.name, name);
    EXPECT_FALSE(tf.colors.empty()) << name;
    EXPECT_FALSE(tf.opacities.empty()) << name;
    expectSameTf(tf, TransferFunction::fromJson(tf.toJson()));
    const fs::path path = dir.file(name + ".json");
    tf.save(path);
    expectSameTf(tf, TransferFunction::load(path));
    expectSameTf(tf, TransferFunction::fromPresetOrFile(path.string()));
    expectSameTf(tf, TransferFunction::fromPresetOrFile(name));
  }
}

TEST(TransferFunction, PresetsHaveTheirSpecifiedShapes) {
  const TransferFunction grey = TransferFunction::preset("grey");
  EXPECT_EQ(grey.opacity(0.0), 0.0);
  EXPECT_NEAR(grey.opacity(0.5), 0.025, 1e-15);
  EXPECT_EQ(grey.opacity(1.0), 0.05);
  EXPECT_EQ(grey.color(0.0), glm::dvec3(0.0));
  EXPECT_EQ(grey.color(1.0), glm::dvec3(1.0));
  EXPECT_NEAR(grey.color(0.3).g, 0.3, 1e-15);

  const TransferFunction bench = TransferFunction::preset("bench");
  EXPECT_EQ(bench.opacity(0.1), 0.0);
  EXPECT_EQ(bench.opacity(0.2), 0.0);
  EXPECT_NEAR(bench.opacity(0.6), 0.1, 1e-15);
  EXPECT_EQ(bench.opacity(1.0), 0.2);
  EXPECT_NEAR(bench.color(0.6).r, 0.6, 1e-15);
  EXPECT_EQ(bench.opacityUnitLength, 1.0);

  const TransferFunction mr = TransferFunction::preset("mr-default");
  EXPECT_EQ(mr.opacity(0.05), 0.0);  // air and noise
  EXPECT_EQ(mr.opacity(0.12), 0.0);
  EXPECT_GE(mr.opacity(0.5), 0.1);
  EXPECT_LE(mr.opacity(1.0), 0.3);
  const glm::dvec3 skin = mr.color(0.3);
  EXPECT_GT(skin.r, skin.g);  // warm flesh tone
  EXPECT_GT(skin.g, skin.b);
  EXPECT_GT(mr.color(0.9).b, skin.b);  // brighter / whiter at the top

  const TransferFunction bone = TransferFunction::preset("ct-bone");
  EXPECT_EQ(bone.opacity(0.3), 0.0);
  EXPECT_EQ(bone.opacity(0.45), 0.0);
  EXPECT_GE(bone.opacity(0.6), 0.5);
  EXPECT_EQ(bone.opacity(1.0), 0.8);
  EXPECT_GT(bone.color(0.8).b, 0.8);  // ivory/white

  const TransferFunction muscle = TransferFunction::preset("ct-muscle");
  EXPECT_EQ(muscle.opacity(0.2), 0.0);
  EXPECT_GT(muscle.opacity(0.4), 0.0);
  EXPECT_LT(muscle.opacity(0.4), 0.2);                        // semi-transparent soft tissue
  EXPECT_GT(muscle.color(0.4).r, 2.0 * muscle.color(0.4).b);  // red/pink
  EXPECT_GE(muscle.opacity(0.8), 0.6);                        // opaque bone
  EXPECT_GT(muscle.color(0.8).b, 0.8);
}

TEST(TransferFunction, UnknownPresetListsTheValidNames) {
  const std::string msg = inputErrorMessage([] { TransferFunction::preset("ct-liver"); });
  EXPECT_NE(msg.find("ct-liver"), std::string::npos) << msg;
  for (const std::string& name : TransferFunction::presetNames()) {
    EXPECT_NE(msg.find(name), std::string::npos) << msg;
  }
}

TEST(TransferFunction, FromPresetOrFileRejectsWhatIsNeither) {
  std::string msg = inputErrorMessage([] { TransferFunction::fromPresetOrFile("bone"); });
  EXPECT_NE(msg.find("bone"), std::string::npos) << msg;
  EXPECT_NE(msg.find("ct-bone"), std::string::npos) << msg;  // the list of presets

  TempDir dir;
  const fs::path missing = dir.file("missing.json");
  msg = inputErrorMessage([&] { TransferFunction::fromPresetOrFile(missing.string()); });
  EXPECT_NE(msg.find(missing.string()), std::string::npos) << msg;
}

TEST(TransferFunction, MalformedJsonFileNamesThePathAndTheParserError) {
  TempDir dir;
  const fs::path path = dir.file("broken.json");
  writeText(path, R"({"name": "x", "color": [{"x": 0, "rgb": [0, 0, 0]}, )");
  const std::string msg = inputErrorMessage([&] { TransferFunction::load(path); });
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("parse error"), std::string::npos) << msg;  // nlohmann's own message
  EXPECT_NE(msg.find("line 1"), std::string::npos) << msg;
}

TEST(TransferFunction, InvalidValuesInAFileAreRejectedNamingThePath) {
  const std::string goodColor = R"("color": [{"x": 0, "rgb": [0, 0, 0]}])";
  const std::string goodOpacity = R"("opacity": [{"x": 0, "alpha": 0.5}])";
  struct Case {
    std::string json;
    std::string mentions;  // part of the message that locates the problem
  };
  const std::vector<Case> cases = {
      {R"({"color": [{"x": 1.5, "rgb": [0, 0, 0]}], )" + goodOpacity + "}", "color[0]"},
      {R"({"color": [{"x": -0.1, "rgb": [0, 0, 0]}], )" + goodOpacity + "}", "color[0]"},
      {R"({"color": [{"x": 0, "rgb": [0, 0, 0]}, {"x": 1, "rgb": [0, 2, 0]}], )" + goodOpacity +
           "}",
       "color[1]"},
      {R"({"color": [{"x": 0, "rgb": [0, 0]}], )" + goodOpacity + "}", "rgb"},
      {R"({"color": [{"x": 0, "rgb": [0, "red", 0]}], )" + goodOpacity + "}", "rgb"},
      {R"({"color": [{"x": "0", "rgb": [0, 0, 0]}], )" + goodOpacity + "}", "x"},
      {"{" + goodColor + R"(, "opacity": [{"x": 0, "alpha": 1.2}]})", "opacity[0]"},
      {"{" + goodColor + R"(, "opacity": [{"x": 0, "alpha": -0.2}]})", "opacity[0]"},
      {"{" + goodColor + R"(, "opacity": [{"x": 0}]})", "alpha"},
      {"{" + goodColor + R"(, "opacity": []})", "opacity"},
      {"{" + goodColor + "}", "opacity"},
      {"{" + goodOpacity + "}", "color"},
      {R"({"color": [], )" + goodOpacity + "}", "color"},
      {"{" + goodColor + ", " + goodOpacity + R"(, "opacity_unit_length": 0})",
       "opacity_unit_length"},
      {"{" + goodColor + ", " + goodOpacity + R"(, "opacity_unit_length": -1})",
       "opacity_unit_length"},
      {"{" + goodColor + ", " + goodOpacity + R"(, "opacity_unit_length": 1e400})", "1e400"},
      {"{" + goodColor + ", " + goodOpacity + R"(, "opacity_unit_lenght": 2})",
       "opacity_unit_lenght"},
      {"{" + goodColor + ", " + goodOpacity + R"(, "name": 3})", "name"},
      {"[1, 2, 3]", "object"},
  };
  TempDir dir;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path path = dir.file("bad" + std::to_string(i) + ".json");
    writeText(path, cases[i].json);
    const std::string msg = inputErrorMessage([&] { TransferFunction::load(path); });
    EXPECT_NE(msg.find(path.string()), std::string::npos) << cases[i].json << "\n" << msg;
    EXPECT_NE(msg.find(cases[i].mentions), std::string::npos) << cases[i].json << "\n" << msg;
  }
  // The same texts are fine once repaired: the valid skeleton itself loads.
  const fs::path good = dir.file("good.json");
  writeText(good, "{" + goodColor + ", " + goodOpacity + R"(, "opacity_unit_length": 2.5})");
  const TransferFunction tf = TransferFunction::load(good);
  EXPECT_EQ(tf.opacityUnitLength, 2.5);
  EXPECT_EQ(tf.opacity(0.7), 0.5);
}

TEST(TransferFunction, FromJsonSortsUnorderedPointsStably) {
  const TransferFunction tf = TransferFunction::fromJson(R"({
    "color": [{"x": 1, "rgb": [1, 1, 1]}, {"x": 0, "rgb": [0, 0, 0]}],
    "opacity": [{"x": 1, "alpha": 1}, {"x": 0.5, "alpha": 0}, {"x": 0.5, "alpha": 0.8},
                {"x": 0, "alpha": 0}]})");
  EXPECT_EQ(tf.name, "custom");
  EXPECT_EQ(tf.opacityUnitLength, 1.0);
  EXPECT_NEAR(tf.color(0.25).r, 0.25, 1e-15);
  EXPECT_EQ(tf.opacity(0.25), 0.0);
  EXPECT_EQ(tf.opacity(0.5), 0.8);  // the later of the two 0.5 points wins
  EXPECT_NEAR(tf.opacity(0.75), 0.9, 1e-15);
}

TEST(TransferFunction, LoadOfAMissingFileNamesIt) {
  TempDir dir;
  const fs::path path = dir.file("nope.json");
  const std::string msg = inputErrorMessage([&] { TransferFunction::load(path); });
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
}

TEST(TransferFunction, SaveIntoAMissingDirectoryThrowsNamingThePath) {
  TempDir dir;
  const fs::path path = dir.file("no-such-dir") / "tf.json";
  try {
    TransferFunction::preset("grey").save(path);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera
