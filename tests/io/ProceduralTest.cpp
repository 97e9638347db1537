#include "tessera/io/Procedural.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "io/IoFixtures.h"
#include "tessera/core/Error.h"

namespace tessera {
namespace {

// Value of the voxel whose cell contains the phantom point p in [-1, 1]^3.
double sheppLoganAt(const Volume& v, glm::dvec3 p) {
  const glm::ivec3 d = v.dims();
  glm::ivec3 i;
  for (int a = 0; a < 3; ++a) {
    i[a] = std::clamp(static_cast<int>(std::floor((p[a] + 1.0) * 0.5 * d[a])), 0, d[a] - 1);
  }
  return v.valueAt(i.x, i.y, i.z);
}

TEST(SheppLogan, RegionsHaveTheModifiedContrastIntensities) {
  const Volume v = makeSheppLogan({64, 64, 64});
  EXPECT_EQ(v.dims(), glm::ivec3(64));
  EXPECT_EQ(v.type(), ScalarType::U8);
  // Intensities sum over the ellipsoids containing a point (Toft's contrast):
  // skull 1, brain 1 - 0.8 = 0.2, ventricles 0.2 - 0.2 = 0, ellipsoid 5 0.3;
  // the skull maps to 255.
  EXPECT_EQ(sheppLoganAt(v, {0.95, 0.95, 0.95}), 0.0);   // outside the head
  EXPECT_EQ(sheppLoganAt(v, {0.0, 0.0, 0.0}), 51.0);     // brain
  EXPECT_EQ(sheppLoganAt(v, {0.0, 0.89, 0.0}), 255.0);   // skull, between ellipsoids 1 and 2
  EXPECT_EQ(sheppLoganAt(v, {0.22, 0.0, 0.0}), 0.0);     // right ventricle centre
  EXPECT_EQ(sheppLoganAt(v, {-0.22, 0.0, 0.0}), 0.0);    // left ventricle centre
  EXPECT_EQ(sheppLoganAt(v, {0.0, 0.35, -0.15}), 77.0);  // ellipsoid 5: 0.3
  EXPECT_EQ(v.valueRange().max, 255.0);
  EXPECT_EQ(v.valueRange().min, 0.0);
  EXPECT_DOUBLE_EQ(v.spacing().x, 1.0);  // voxel units along the longest axis
  EXPECT_EQ(v.description(), "generated: shepp-logan 64x64x64");
}

TEST(SheppLogan, SmallEllipsoidsAppearAtHigherResolution) {
  const Volume v = makeSheppLogan({128, 128, 128});
  EXPECT_EQ(sheppLoganAt(v, {0.0, 0.1, 0.25}), 77.0);    // ellipsoid 6
  EXPECT_EQ(sheppLoganAt(v, {0.0, -0.1, 0.25}), 77.0);   // ellipsoid 7
  EXPECT_EQ(sheppLoganAt(v, {0.0, -0.606, 0.0}), 77.0);  // ellipsoid 9
  EXPECT_EQ(sheppLoganAt(v, {0.0, -0.45, 0.0}), 51.0);   // plain brain between them
}

TEST(SheppLogan, NonCubicSizesKeepTheShape) {
  const Volume v = makeSheppLogan({64, 32, 16});
  EXPECT_EQ(v.dims(), glm::ivec3(64, 32, 16));
  EXPECT_EQ(v.spacing(), glm::dvec3(1.0, 2.0, 4.0));  // a cube in world space
  EXPECT_EQ(sheppLoganAt(v, {0.0, 0.0, 0.0}), 51.0);
  EXPECT_EQ(sheppLoganAt(v, {0.22, 0.0, 0.0}), 0.0);
}

TEST(Sphere, InsideIsFullOutsideIsEmptyEdgeIsSmooth) {
  const Volume v = makeSphere({32, 32, 32});
  EXPECT_EQ(v.type(), ScalarType::U8);
  EXPECT_EQ(v.description(), "generated: sphere 32x32x32");
  const double radius = 0.4 * 32;  // 12.8 voxels around the centre (15.5, 15.5, 15.5)
  int partial = 0;
  for (int z = 0; z < 32; ++z) {
    for (int x = 0; x < 32; ++x) {
      const double dist = std::sqrt((x - 15.5) * (x - 15.5) + 0.25 + (z - 15.5) * (z - 15.5));
      const double got = v.valueAt(x, 15, z);
      if (dist < radius - 0.5) {
        EXPECT_EQ(got, 255.0) << x << "," << z;
      }
      if (dist > radius + 0.5) {
        EXPECT_EQ(got, 0.0) << x << "," << z;
      }
      if (got > 0.0 && got < 255.0) ++partial;
    }
  }
  EXPECT_GT(partial, 0) << "the edge should be anti-aliased";
}

TEST(Sphere, RadiusFollowsTheSmallestExtent) {
  const Volume v = makeSphere({64, 64, 10});  // radius 4 voxels
  EXPECT_EQ(v.valueAt(31, 31, 5), 255.0);
  EXPECT_EQ(v.valueAt(31 + 6, 31, 5), 0.0);
  EXPECT_EQ(v.valueAt(31, 31 - 6, 5), 0.0);
}

// Marschner & Lobb 1994, eq. 2, written out independently of the generator.
double mlReference(double x, double y, double z) {
  const double pi = std::numbers::pi;
  const double fm = 6.0, alpha = 0.25;
  const double r = std::hypot(x, y);
  const double rho = std::cos(2 * pi * fm * std::cos(pi * r / 2));
  return (1 - std::sin(pi * z / 2) + alpha * (1 + rho)) / (2 * (1 + alpha));
}

TEST(MarschnerLobb, MatchesTheFormulaAtSamplePoints) {
  const Volume v = makeMarschnerLobb({41, 41, 41});
  EXPECT_EQ(v.type(), ScalarType::F32);
  EXPECT_DOUBLE_EQ(v.spacing().x, 1.0);
  const int samples[][3] = {{0, 0, 0},   {20, 20, 20}, {40, 40, 40},
                            {3, 17, 29}, {40, 0, 20},  {11, 33, 5}};
  for (const auto& s : samples) {
    const double x = -1 + 0.05 * s[0], y = -1 + 0.05 * s[1], z = -1 + 0.05 * s[2];
    EXPECT_NEAR(v.valueAt(s[0], s[1], s[2]), mlReference(x, y, z), 1e-6)
        << s[0] << "," << s[1] << "," << s[2];
  }
  // At the centre: r = 0, so rho_r = cos(12 pi) = 1 and the value is
  // (1 - 0 + 0.25 * 2) / 2.5 = 0.6.
  EXPECT_NEAR(v.valueAt(20, 20, 20), 0.6, 1e-6);
  EXPECT_GE(v.valueRange().min, 0.0);
  EXPECT_LE(v.valueRange().max, 1.0);
}

TEST(MarschnerLobb, EveryVoxelOfAThreadedVolumeMatchesTheFormula) {
  const glm::ivec3 d(72, 70, 68);  // large enough to be filled by several threads
  const Volume v = makeMarschnerLobb(d);
  double worst = 0.0;
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x) {
        const double e = mlReference(-1 + 2.0 * x / (d.x - 1), -1 + 2.0 * y / (d.y - 1),
                                     -1 + 2.0 * z / (d.z - 1));
        worst = std::max(worst, std::abs(v.valueAt(x, y, z) - e));
      }
    }
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(Procedural, ParsesSpecsAndDefaults) {
  EXPECT_EQ(makeProcedural("gen:shepp-logan").dims(), glm::ivec3(64));
  EXPECT_EQ(makeProcedural("gen:marschner-lobb").dims(), glm::ivec3(41));
  EXPECT_EQ(makeProcedural("gen:sphere:16").dims(), glm::ivec3(16));
  const Volume v = makeProcedural("gen:marschner-lobb:8x9x10");
  EXPECT_EQ(v.dims(), glm::ivec3(8, 9, 10));
  EXPECT_EQ(v.description(), "generated: marschner-lobb 8x9x10");
  EXPECT_EQ(makeProcedural("gen:sphere:1").dims(), glm::ivec3(1));
}

TEST(Procedural, RejectsBadSpecs) {
  for (const std::string spec :
       {"gen:", "gen:cube", "gen:cube:16", "gen:sphere:", "gen:sphere:0", "gen:sphere:-4",
        "gen:sphere:abc", "gen:sphere:4x4", "gen:sphere:4x4x4x4", "gen:sphere:4xx4",
        "gen:sphere:99999999999", "gen:sphere:2000000", "gen:sphere:16:2", "gen:sphere: 16",
        "gen:Sphere", "sphere"}) {
    test::expectRejected<InputError>([&] { makeProcedural(spec); }, {spec});
  }
}

TEST(Procedural, AllocationGoesThroughTheHostBudget) {
  test::BudgetOverride budget(1 << 20);
  test::expectRejected<BudgetError>([] { makeProcedural("gen:shepp-logan:1024"); },
                                    {"gen:shepp-logan", "budget"});
}

}  // namespace
}  // namespace tessera
