// Overlay lines: geometry, the GPU line layer (colour + distance along the
// pixel ray), and the CPU ground truth that terminates rays at the lines.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/geometric.hpp>

#include "support/GpuTestContext.h"
#include "support/TestTransferFunctions.h"
#include "tessera/core/Error.h"
#include "tessera/io/Procedural.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceOverlay.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Overlay.h"
#include "tessera/render/OverlayRenderer.h"

using namespace tessera;

namespace {

TransferFunction tintedTf() {
  return test::tfFromPoints(
      {{0.0, {0.0, 0.0, 0.0}}, {0.5, {0.2, 0.5, 0.9}}, {1.0, {1.0, 0.8, 0.3}}},
      {{0.02, 0.0}, {0.3, 0.1}, {1.0, 0.3}});
}

// Distance from point p to segment ab.
double segmentDistance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b) {
  const glm::dvec3 ab = b - a;
  const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
  return glm::length(p - (a + t * ab));
}

}  // namespace

TEST(Overlay, ParsesTheOverlayListAndRejectsUnknownNames) {
  const render::OverlayOptions o = render::OverlayOptions::parse("box,roi");
  EXPECT_TRUE(o.box);
  EXPECT_FALSE(o.axes);
  EXPECT_TRUE(o.roi);
  EXPECT_EQ(o.describe(), "box,roi");
  EXPECT_FALSE(render::OverlayOptions::parse("none").any());
  EXPECT_THROW(render::OverlayOptions::parse("box,grid"), InputError);

  const Volume v = makeSphere({40, 20, 10});
  render::OverlayOptions roi;
  roi.setRoiVoxels("10:30,0:20,5:10", v);
  EXPECT_DOUBLE_EQ(roi.roiMin.x, 0.25);
  EXPECT_DOUBLE_EQ(roi.roiMax.z, 1.0);
  EXPECT_THROW(roi.setRoiVoxels("10:50,0:20,5:10", v), InputError);
  EXPECT_THROW(roi.setRoiVoxels("10-30", v), InputError);
}

TEST(Overlay, BoxAxesAndRoiHaveTheirSegments) {
  const Volume v = makeSphere({32, 32, 16});
  render::OverlayOptions o = render::OverlayOptions::parse("box,axes,roi");
  const auto lines = render::overlayLines(v, o);
  ASSERT_EQ(lines.size(), 12u + 3u + 12u);
  // Box corners lie on the world box; axes start at the centre.
  const glm::dvec3 half = 0.5 * v.extent();
  for (int i = 0; i < 12; ++i) {
    EXPECT_DOUBLE_EQ(std::abs(lines[static_cast<std::size_t>(i)].a.x), half.x);
    EXPECT_DOUBLE_EQ(std::abs(lines[static_cast<std::size_t>(i)].b.z), half.z);
  }
  EXPECT_EQ(lines[12].a, glm::dvec3(0.0));
  EXPECT_DOUBLE_EQ(lines[14].b.z, 1.3 * half.z);
}

// Where a ray enters the box of `extent` centred at the origin (its ray
// parameter), or +infinity when it misses.
double boxEntry(const Ray& r, glm::dvec3 extent) {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (r.direction[a] == 0.0) {
      if (std::abs(r.origin[a]) > 0.5 * extent[a]) return hi;
      continue;
    }
    const double t0 = (-0.5 * extent[a] - r.origin[a]) / r.direction[a];
    const double t1 = (0.5 * extent[a] - r.origin[a]) / r.direction[a];
    lo = std::max(lo, std::min(t0, t1));
    hi = std::min(hi, std::max(t0, t1));
  }
  return lo < hi ? lo : std::numeric_limits<double>::infinity();
}

// Every line pixel's distance, taken along that pixel's ray, lands on a line
// segment (within the pixel's footprint): the packing, the projection and the
// ray parameter agree with Camera::pixelRay. Its alpha says whether the line
// is in front of the volume box as the CPU says from that distance and the
// pixel's ray (up to lines within a pixel's footprint of the threshold).
TEST(Overlay, LineLayerDistanceLiesOnTheLines) {
  gpu::GlContext& c = test::gpuContext();
  const Volume v = makeSphere({48, 40, 32});
  const auto lines = render::overlayLines(v, render::OverlayOptions::parse("box,axes,roi"));
  for (Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    Camera cam;
    cam.frame(v.extent());
    cam.azimuthDeg = 35;
    cam.elevationDeg = 25;
    cam.projection = projection;
    const int w = 160, h = 120;
    render::OverlayRenderer overlay(c);
    overlay.draw(lines, cam, w, h, v.extent());
    const Image color = overlay.readColor();
    const double tolerance = render::overlayFrontTolerance(cam, h, v.extent());
    const std::vector<float> dist = overlay.readDistance();
    // World size of one pixel at the target's distance.
    const double pixel =
        2.0 * cam.orthoHalfHeight() / h * (projection == Projection::Perspective ? 1.3 : 1.0);
    int linePixels = 0;
    int front = 0;
    int behind = 0;
    int borderline = 0;
    double worst = 0.0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        const int alpha = color.pixel(x, y)[3];
        if (alpha == 0) {
          EXPECT_TRUE(std::isinf(dist[i]));
          continue;
        }
        ++linePixels;
        const Ray r = cam.pixelRay(x, y, w, h);
        const double entry = boxEntry(r, v.extent());
        const double threshold = std::max(entry, 0.0) + tolerance;
        const bool inFront = std::isinf(entry) || dist[i] <= threshold;
        if (std::abs(dist[i] - threshold) < pixel) {
          ++borderline;
        } else {
          EXPECT_EQ(alpha, inFront ? 255 : 128) << x << "," << y;
        }
        (inFront ? front : behind)++;
        const glm::dvec3 p = r.origin + static_cast<double>(dist[i]) * r.direction;
        double nearest = std::numeric_limits<double>::infinity();
        for (const auto& l : lines) nearest = std::min(nearest, segmentDistance(p, l.a, l.b));
        worst = std::max(worst, nearest);
      }
    }
    std::printf(
        "  [measured] %s: %d line pixels (%d in front of the box, %d in or behind it, %d within a "
        "pixel of the threshold), farthest from a segment %.3f (pixel %.3f)\n",
        projection == Projection::Perspective ? "perspective" : "orthographic", linePixels, front,
        behind, borderline, worst, pixel);
    EXPECT_GT(linePixels, 600);
    EXPECT_GT(front, 100);
    EXPECT_GT(behind, 100);
    EXPECT_LT(borderline, linePixels / 10);
    EXPECT_LT(worst, 1.5 * pixel);
  }
}

// The ground truth's two limits are exact: a line nearer than the volume is
// unattenuated; a line beyond the volume is the background of the ordinary
// reference; and a line half-way through is attenuated by the front part.
TEST(Overlay, ReferenceTerminatesRaysAtTheLine) {
  const Volume v = makeSheppLogan({32, 32, 32});
  const TransferFunction tf = tintedTf();
  Camera cam;
  cam.frame(v.extent());
  cam.azimuthDeg = 20;
  RenderSettings s;
  s.ertThreshold = 2.0;
  const int n = 48;
  Image lineColor(n, n);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      std::uint8_t* p = lineColor.pixel(x, y);
      p[0] = 255, p[1] = 64, p[2] = 0, p[3] = 255;
    }
  }
  const double eyeDist = glm::length(cam.eye());
  const std::vector<float> nearLine(n * n, static_cast<float>(eyeDist - 2.0 * cam.radius));
  const std::vector<float> farLine(n * n, static_cast<float>(eyeDist + 2.0 * cam.radius));
  const std::vector<float> midLine(n * n, static_cast<float>(eyeDist));

  const Image inFront = renderReferenceWithLines(v, tf, cam, s, n, n, lineColor, nearLine);
  EXPECT_TRUE(std::isinf(psnr(inFront, lineColor)));

  RenderSettings overLine = s;
  overLine.background = glm::dvec4(1.0, 64.0 / 255.0, 0.0, 1.0);
  const Image behind = renderReferenceWithLines(v, tf, cam, s, n, n, lineColor, farLine);
  EXPECT_TRUE(std::isinf(psnr(behind, renderReference(v, tf, cam, overLine, n, n))));

  // Half-way: brighter red than behind the whole volume where the volume is
  // thick, since only its front half attenuates the line.
  const Image inside = renderReferenceWithLines(v, tf, cam, s, n, n, lineColor, midLine);
  const std::uint8_t* centreInside = inside.pixel(n / 2, n / 2);
  const std::uint8_t* centreBehind = behind.pixel(n / 2, n / 2);
  const std::uint8_t* centreFront = inFront.pixel(n / 2, n / 2);
  std::printf("  [measured] centre red: in front %d, inside %d, behind %d\n", centreFront[0],
              centreInside[0], centreBehind[0]);
  EXPECT_GT(centreInside[0], centreBehind[0] + 10);
  EXPECT_LT(centreInside[0], centreFront[0]);
}
