// The shading gradient's plan (layout/GradientTexture.h): precomputed where
// ES 3's 3D textures and the budget hold it, on the fly otherwise, each with
// its reason; asking for precomputed where it cannot be had is an error.
#include <gtest/gtest.h>

#include "tessera/core/Error.h"
#include "tessera/layout/GradientTexture.h"

using namespace tessera;
using layout::GradientWish;
using layout::planGradient;

namespace {
const glm::ivec3 kCh2{181, 217, 181};
constexpr std::uint64_t kCh2GradientBytes = 4ull * 181 * 217 * 181;
constexpr std::uint64_t kMiB = 1024 * 1024;
}  // namespace

TEST(GradientPlan, PrecomputedWhereTheBudgetHoldsIt) {
  const layout::GradientPlan p = planGradient(GradientWish::Auto, kCh2, "texture3d",
                                              gpu::ApiLevel::Gles3, 1024, 512 * kMiB, 10 * kMiB);
  EXPECT_TRUE(p.precomputed);
  EXPECT_EQ(p.texture.bytes, kCh2GradientBytes);
  EXPECT_EQ(p.texture.format, "RGBA8");
  EXPECT_NE(p.reason.find("precomputed"), std::string::npos) << p.reason;
  // Unlimited budget (0), and every Cartesian layout.
  for (const char* name : {"texture3d", "mosaic", "packed-mosaic"}) {
    EXPECT_TRUE(
        planGradient(GradientWish::Auto, kCh2, name, gpu::ApiLevel::Gles3, 2048, 0, 0).precomputed)
        << name;
  }
}

TEST(GradientPlan, OnTheFlyWithItsReasonOtherwise) {
  struct Case {
    const char* layout;
    gpu::ApiLevel api;
    int max3D;
    std::uint64_t budget;
    std::uint64_t inUse;
    const char* why;
  };
  const Case cases[] = {
      {"mosaic", gpu::ApiLevel::Gles2, 0, 0, 0, "no 3D textures"},
      {"texture3d", gpu::ApiLevel::Gles3, 1024, 128 * kMiB, 110 * kMiB, "budget"},
      {"texture3d", gpu::ApiLevel::Gles3, 128, 0, 0, "3D texture size 128"},
      {"bricks", gpu::ApiLevel::Gles3, 2048, 0, 0, "bricks layout"},
      {"fcc", gpu::ApiLevel::Gles3, 2048, 0, 0, "fcc layout"},
  };
  for (const Case& c : cases) {
    const layout::GradientPlan p =
        planGradient(GradientWish::Auto, kCh2, c.layout, c.api, c.max3D, c.budget, c.inUse);
    EXPECT_FALSE(p.precomputed) << c.why;
    EXPECT_NE(p.reason.find("on the fly"), std::string::npos) << p.reason;
    EXPECT_NE(p.reason.find(c.why), std::string::npos) << p.reason;
    EXPECT_THROW(
        planGradient(GradientWish::Precomputed, kCh2, c.layout, c.api, c.max3D, c.budget, c.inUse),
        InputError)
        << c.why;
  }
  // Asked for on the fly: so, even where the texture would fit.
  EXPECT_FALSE(
      planGradient(GradientWish::OnTheFly, kCh2, "texture3d", gpu::ApiLevel::Gles3, 2048, 0, 0)
          .precomputed);
  EXPECT_THROW(layout::parseGradientWish("fast"), InputError);
}
