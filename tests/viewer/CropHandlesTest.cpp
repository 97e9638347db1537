#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "tessera/viewer/CropHandles.h"

namespace tessera::viewer {
namespace {

constexpr int kW = 400, kH = 400;
const glm::dvec3 kExtent{100.0, 100.0, 100.0};

Camera orthoCamera() {
  Camera c;
  c.frame(kExtent);
  c.projection = Projection::Orthographic;
  return c;
}

glm::dvec2 handlePixel(const Camera& c, const Clipping& clip, int face) {
  return projectToScreen(c, CropHandles::faceCentre(clip, kExtent, face), kW, kH)->pixel;
}

// projectToScreen inverts Camera::pixelRay: a point on a pixel's ray lands
// on that pixel's centre, in both projections.
TEST(CropHandles, ProjectionInvertsPixelRays) {
  for (Projection proj : {Projection::Perspective, Projection::Orthographic}) {
    Camera c;
    c.frame(kExtent);
    c.projection = proj;
    c.azimuthDeg = 35.0;
    c.elevationDeg = -20.0;
    for (glm::ivec2 px : {glm::ivec2(10, 20), glm::ivec2(200, 200), glm::ivec2(390, 333)}) {
      const Ray r = c.pixelRay(px.x, px.y, kW, kH);
      const auto s = projectToScreen(c, r.origin + 250.0 * r.direction, kW, kH);
      ASSERT_TRUE(s.has_value());
      EXPECT_NEAR(s->pixel.x, px.x + 0.5, 1e-9);
      EXPECT_NEAR(s->pixel.y, px.y + 0.5, 1e-9);
    }
  }
}

// Looking at the face (azimuth 0), the patient's right is on the screen's
// left: with RAS storage index +x is Right, so its handle is left of the
// centre; with mirrored storage (index +x = Left, +y = Posterior) it is on
// the right. Superior (+z) is up in both.
TEST(CropHandles, HandlesSitOnThePatientsSides) {
  Clipping clip;
  Camera ras = orthoCamera();
  EXPECT_LT(handlePixel(ras, clip, 1).x, kW / 2.0 - 50.0);
  EXPECT_GT(handlePixel(ras, clip, 0).x, kW / 2.0 + 50.0);
  EXPECT_LT(handlePixel(ras, clip, 5).y, kH / 2.0 - 50.0);
  Camera lps = orthoCamera();
  lps.modelFromWorld = glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1));
  EXPECT_GT(handlePixel(lps, clip, 1).x, kW / 2.0 + 50.0);
  EXPECT_LT(handlePixel(lps, clip, 0).x, kW / 2.0 - 50.0);
}

TEST(CropHandles, HitFindsTheNearestHandleAndPrefersTheFrontOne) {
  Clipping clip;
  const Camera c = orthoCamera();
  for (int f = 0; f < kCropFaces; ++f) {
    const glm::dvec2 p = handlePixel(c, clip, f);
    if (f == 2 || f == 3) continue;  // the y faces overlap at the centre
    EXPECT_EQ(CropHandles::hit(c, clip, kExtent, p + glm::dvec2(3.0, -4.0), kW, kH, 12.0), f);
    EXPECT_FALSE(CropHandles::hit(c, clip, kExtent, p + glm::dvec2(13.0, 0.0), kW, kH, 12.0));
  }
  // Anterior (+y, face 3) and posterior (-y) both project to the centre;
  // the camera looks from anterior, so the anterior handle is taken.
  EXPECT_EQ(CropHandles::hit(c, clip, kExtent, {kW / 2.0, kH / 2.0}, kW, kH), 3);
}

// Orthographic, zoom 1: the view's half height is the framed radius
// (half the box's diagonal), so 1 mm is (kH / 2) / radius pixels.
TEST(CropHandles, DragMovesTheGrabbedFaceByTheProjectedMotion) {
  Clipping clip;
  clip.cropMin = glm::dvec3(0.2);
  clip.cropMax = glm::dvec3(0.8);
  const Camera c = orthoCamera();
  const double pxPerUnit = 100.0 * (kH / 2.0) / c.radius;  // one axis = 100 mm
  CropHandles drag;
  const int face = 1;  // +x: patient right, on the screen's left
  const glm::dvec2 start = handlePixel(c, clip, face);
  ASSERT_EQ(CropHandles::hit(c, clip, kExtent, start, kW, kH), face);
  drag.begin(c, clip, kExtent, face, start, kW, kH);
  // 0.2 of the axis towards the screen's right (towards the patient's
  // left, i.e. inwards), plus vertical motion that must be ignored.
  EXPECT_TRUE(drag.move(start + glm::dvec2(0.2 * pxPerUnit, 37.0), clip));
  EXPECT_NEAR(clip.cropMax.x, 0.6, 1e-9);
  EXPECT_EQ(clip.cropMin, glm::dvec3(0.2));
  EXPECT_EQ(clip.cropMax.y, 0.8);
  EXPECT_EQ(clip.cropMax.z, 0.8);
  // The handle followed the mouse along x.
  EXPECT_NEAR(handlePixel(c, clip, face).x, start.x + 0.2 * pxPerUnit, 1e-6);
  // Superior face dragged up by 0.1 of the axis.
  drag.end();
  const glm::dvec2 top = handlePixel(c, clip, 5);
  drag.begin(c, clip, kExtent, 5, top, kW, kH);
  EXPECT_TRUE(drag.move(top - glm::dvec2(0.0, 0.1 * pxPerUnit), clip));
  EXPECT_NEAR(clip.cropMax.z, 0.9, 1e-9);
}

TEST(CropHandles, DragIsClampedToTheVolumeAndTheOppositeFace) {
  Clipping clip;
  clip.cropMin = glm::dvec3(0.3);
  clip.cropMax = glm::dvec3(0.7);
  const Camera c = orthoCamera();
  CropHandles drag;
  const glm::dvec2 p = handlePixel(c, clip, 1);
  drag.begin(c, clip, kExtent, 1, p, kW, kH);
  drag.move(p + glm::dvec2(1000.0, 0.0), clip);  // past the -x face
  EXPECT_NEAR(clip.cropMax.x, 0.3 + CropHandles::kMinGap, 1e-12);
  drag.move(p - glm::dvec2(1000.0, 0.0), clip);  // out of the volume
  EXPECT_EQ(clip.cropMax.x, 1.0);
  drag.end();
  const glm::dvec2 q = handlePixel(c, clip, 0);
  drag.begin(c, clip, kExtent, 0, q, kW, kH);
  drag.move(q + glm::dvec2(1000.0, 0.0), clip);
  EXPECT_EQ(clip.cropMin.x, 0.0);
  // An axis seen end-on cannot be dragged: y from the front.
  drag.end();
  const glm::dvec2 y = handlePixel(c, clip, 3);
  drag.begin(c, clip, kExtent, 3, y, kW, kH);
  EXPECT_FALSE(drag.move(y + glm::dvec2(40.0, 40.0), clip));
  EXPECT_EQ(clip.cropMax.y, 0.7);
}

// The box's edges run along the crop box and the handles' crosses sit at
// the face centres.
TEST(CropHandles, LinesOutlineTheCropBox) {
  Clipping clip;
  clip.cropMin = {0.1, 0.2, 0.3};
  clip.cropMax = {0.6, 0.7, 0.9};
  const auto lines = CropHandles::lines(clip, kExtent, 2);
  ASSERT_EQ(lines.size(), 12u + 2u * kCropFaces);
  const glm::dvec3 lo = (clip.cropMin - 0.5) * kExtent, hi = (clip.cropMax - 0.5) * kExtent;
  for (std::size_t i = 0; i < 12; ++i) {
    for (const glm::dvec3& p : {lines[i].a, lines[i].b}) {
      for (int a = 0; a < 3; ++a) {
        EXPECT_TRUE(p[a] == lo[a] || p[a] == hi[a]) << i << " axis " << a;
      }
    }
  }
  for (int f = 0; f < kCropFaces; ++f) {
    const auto& l = lines[12 + 2 * f];
    EXPECT_NEAR(glm::length(0.5 * (l.a + l.b) - CropHandles::faceCentre(clip, kExtent, f)), 0.0,
                1e-12);
  }
}

}  // namespace
}  // namespace tessera::viewer

namespace tessera::viewer {
namespace {

// The camera-facing plane, applied as the renderers apply clip planes
// (clipHalfSpaces / clipKeeps in texture space): a point nearer the viewer
// than the plane is dropped, one beyond it kept; depth 0 passes through the
// volume's centre. From several angles and for mirrored storage.
TEST(CameraFacingPlane, KeepsTheFarSideAndDepthZeroIsTheCentre) {
  const glm::dvec3 extent{120.0, 80.0, 100.0};
  for (bool mirrored : {false, true}) {
    for (double azimuth : {0.0, 70.0, 200.0}) {
      Camera c;
      c.frame(extent);
      if (mirrored)
        c.modelFromWorld =
            glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1));
      c.azimuthDeg = azimuth;
      c.elevationDeg = 25.0;
      for (double depth : {0.0, 15.0, -20.0}) {
        Clipping clipping;
        clipping.planes.push_back(cameraFacingPlane(c, depth));
        const auto h = clipHalfSpaces(clipping, c.modelFromWorld, extent);
        // Model-frame direction towards the viewer, as texture coordinates.
        const glm::dvec3 towardsEye = glm::normalize(c.eye() - c.target);
        auto texture = [&](double alongView) { return (towardsEye * alongView) / extent + 0.5; };
        EXPECT_FALSE(clipKeeps(clipping, h, texture(depth + 1.0))) << azimuth << " " << depth;
        EXPECT_TRUE(clipKeeps(clipping, h, texture(depth - 1.0))) << azimuth << " " << depth;
        if (depth == 0.0) {
          EXPECT_NEAR(glm::dot(glm::dvec3(h[0]), glm::dvec3(0.5)), h[0].w, 1e-9);
        }
      }
    }
  }
}

}  // namespace
}  // namespace tessera::viewer
