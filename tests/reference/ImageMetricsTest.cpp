#include "tessera/reference/ImageMetrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera {
namespace {

Image filled(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b, std::uint8_t a = 255) {
  Image img(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = img.pixel(x, y);
      p[0] = r;
      p[1] = g;
      p[2] = b;
      p[3] = a;
    }
  }
  return img;
}

// Smooth structure plus texture: something SSIM has local variance to see.
Image scene(int w, int h) {
  Image img(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = img.pixel(x, y);
      const double v =
          128.0 + 60.0 * std::sin(x * 0.3) * std::cos(y * 0.2) + ((x / 4 + y / 4) % 2) * 40.0;
      p[0] = static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0));
      p[1] = static_cast<std::uint8_t>(std::clamp(v * 0.8, 0.0, 255.0));
      p[2] = static_cast<std::uint8_t>(std::clamp(255.0 - v, 0.0, 255.0));
      p[3] = 255;
    }
  }
  return img;
}

Image withNoise(const Image& img, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  Image out = img;
  for (std::size_t i = 0; i < out.rgba().size(); ++i) {
    if (i % 4 == 3) continue;
    out.rgba()[i] =
        static_cast<std::uint8_t>(std::clamp(std::lround(out.rgba()[i] + noise(rng)), 0l, 255l));
  }
  return out;
}

// SSIM for the constant images a and b (zero variances): Wang et al. eq. 13
// reduces to the luminance term.
double constantSsim(double a, double b) {
  const double c1 = (0.01 * 255) * (0.01 * 255);
  return (2 * a * b + c1) / (a * a + b * b + c1);
}

// Straightforward 2D evaluation of the same definition, independent of the
// separable implementation: every valid 11x11 window, weights exp(-r^2/2s^2)
// normalised over the window.
double directSsim(const Image& a, const Image& b) {
  const int k = 11;
  const double sigma = 1.5;
  std::vector<double> w(static_cast<std::size_t>(k * k));
  double wsum = 0.0;
  for (int j = 0; j < k; ++j) {
    for (int i = 0; i < k; ++i) {
      const double dx = i - 5, dy = j - 5;
      w[static_cast<std::size_t>(j * k + i)] = std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma));
      wsum += w[static_cast<std::size_t>(j * k + i)];
    }
  }
  auto luma = [](const Image& img, int x, int y) {
    const std::uint8_t* p = img.pixel(x, y);
    return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
  };
  const double c1 = (0.01 * 255) * (0.01 * 255);
  const double c2 = (0.03 * 255) * (0.03 * 255);
  double total = 0.0;
  int count = 0;
  for (int y0 = 0; y0 + k <= a.height(); ++y0) {
    for (int x0 = 0; x0 + k <= a.width(); ++x0) {
      double mx = 0, my = 0, xx = 0, yy = 0, xy = 0;
      for (int j = 0; j < k; ++j) {
        for (int i = 0; i < k; ++i) {
          const double wt = w[static_cast<std::size_t>(j * k + i)] / wsum;
          const double va = luma(a, x0 + i, y0 + j);
          const double vb = luma(b, x0 + i, y0 + j);
          mx += wt * va;
          my += wt * vb;
          xx += wt * va * va;
          yy += wt * vb * vb;
          xy += wt * va * vb;
        }
      }
      const double sx = xx - mx * mx, sy = yy - my * my, sxy = xy - mx * my;
      total += ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sx + sy + c2));
      ++count;
    }
  }
  return total / count;
}

TEST(ImageMetrics, PsnrOfIdenticalImagesIsInfinite) {
  const Image a = scene(32, 24);
  EXPECT_EQ(psnr(a, a), std::numeric_limits<double>::infinity());
  // Alpha is not part of PSNR: images differing only in alpha are identical.
  EXPECT_EQ(psnr(filled(8, 8, 10, 20, 30, 255), filled(8, 8, 10, 20, 30, 0)),
            std::numeric_limits<double>::infinity());
}

TEST(ImageMetrics, PsnrMatchesAKnownMeanSquaredError) {
  // Every RGB sample off by 10: MSE = 100, PSNR = 10 log10(255^2 / 100).
  EXPECT_NEAR(psnr(filled(16, 9, 0, 0, 0), filled(16, 9, 10, 10, 10)),
              10.0 * std::log10(65025.0 / 100.0), 1e-12);
  EXPECT_NEAR(10.0 * std::log10(65025.0 / 100.0), 28.1308036, 1e-7);

  // One sample of one pixel off by 51 in a 10x10 image: MSE = 51^2 / 300.
  const Image a = filled(10, 10, 100, 100, 100);
  Image b = a;
  b.pixel(3, 7)[1] = 151;
  EXPECT_NEAR(psnr(a, b), 10.0 * std::log10(65025.0 / (51.0 * 51.0 / 300.0)), 1e-12);
  EXPECT_DOUBLE_EQ(psnr(a, b), psnr(b, a));

  // Maximal difference everywhere: 0 dB.
  EXPECT_NEAR(psnr(filled(4, 4, 0, 0, 0), filled(4, 4, 255, 255, 255)), 0.0, 1e-12);
}

TEST(ImageMetrics, SsimOfIdenticalImagesIsOne) {
  const Image a = scene(40, 30);
  EXPECT_EQ(ssim(a, a), 1.0);
  EXPECT_EQ(ssim(filled(12, 12, 0, 0, 0), filled(12, 12, 0, 0, 0)), 1.0);
}

TEST(ImageMetrics, SsimOfConstantImagesIsTheLuminanceTerm) {
  // Grey pixels: luminance = the grey value (0.299 + 0.587 + 0.114 = 1).
  EXPECT_NEAR(ssim(filled(20, 20, 100, 100, 100), filled(20, 20, 120, 120, 120)),
              constantSsim(100, 120), 1e-12);
  EXPECT_NEAR(ssim(filled(20, 20, 0, 0, 0), filled(20, 20, 255, 255, 255)), constantSsim(0, 255),
              1e-12);
  EXPECT_LT(constantSsim(0, 255), 1e-3);
}

TEST(ImageMetrics, SsimEqualsTheDirectWindowedDefinition) {
  const Image a = scene(29, 17);
  const Image b = withNoise(a, 12.0, 7);
  const double expected = directSsim(a, b);
  EXPECT_NEAR(ssim(a, b), expected, 1e-12);
  EXPECT_GT(expected, 0.2);
  EXPECT_LT(expected, 0.99);
}

TEST(ImageMetrics, SsimAndPsnrDecreaseWithNoise) {
  const Image clean = scene(64, 48);
  double lastSsim = 1.0;
  double lastPsnr = std::numeric_limits<double>::infinity();
  for (double sigma : {2.0, 6.0, 15.0, 40.0}) {
    const Image noisy = withNoise(clean, sigma, 1234);
    const double s = ssim(clean, noisy);
    const double p = psnr(clean, noisy);
    EXPECT_LT(s, lastSsim) << sigma;
    EXPECT_LT(p, lastPsnr) << sigma;
    EXPECT_GT(s, -1.0) << sigma;
    // Gaussian noise of sigma (little clipping here) has PSNR ~ 20 log10(255 / sigma).
    EXPECT_NEAR(p, 20.0 * std::log10(255.0 / sigma), 1.0) << sigma;
    lastSsim = s;
    lastPsnr = p;
  }
  EXPECT_LT(lastSsim, 0.5);
}

TEST(ImageMetrics, SsimHandlesImagesSmallerThanTheWindow) {
  const Image a = scene(5, 3);
  EXPECT_EQ(ssim(a, a), 1.0);
  EXPECT_NEAR(ssim(filled(5, 3, 100, 100, 100), filled(5, 3, 120, 120, 120)),
              constantSsim(100, 120), 1e-12);
  EXPECT_NEAR(ssim(filled(1, 1, 50, 50, 50), filled(1, 1, 60, 60, 60)), constantSsim(50, 60),
              1e-12);
  // Narrow along one axis only: 40 wide, 4 high.
  const Image wide = scene(40, 4);
  const double s = ssim(wide, withNoise(wide, 20.0, 3));
  EXPECT_TRUE(std::isfinite(s));
  EXPECT_GT(s, 0.0);
  EXPECT_LT(s, 1.0);
}

TEST(ImageMetrics, SizeMismatchOrEmptyImagesThrow) {
  EXPECT_THROW(psnr(Image(4, 4), Image(4, 5)), InputError);
  EXPECT_THROW(ssim(Image(4, 4), Image(5, 4)), InputError);
  EXPECT_THROW(psnr(Image(), Image()), InputError);
  EXPECT_THROW(ssim(Image(0, 3), Image(0, 3)), InputError);
}

}  // namespace
}  // namespace tessera
