#include "tessera/reference/ImageMetrics.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera {

namespace {

void requireComparable(const Image& a, const Image& b, const char* metric) {
  if (a.width() != b.width() || a.height() != b.height()) {
    throw InputError(std::string(metric) + ": image sizes differ (" + std::to_string(a.width()) +
                     "x" + std::to_string(a.height()) + " vs " + std::to_string(b.width()) + "x" +
                     std::to_string(b.height()) + ")");
  }
  if (a.width() == 0 || a.height() == 0) {
    throw InputError(std::string(metric) + ": images are empty (" + std::to_string(a.width()) +
                     "x" + std::to_string(a.height()) + ")");
  }
}

// A w x h plane of doubles, row-major.
struct Plane {
  int w = 0;
  int h = 0;
  std::vector<double> v;
  Plane(int width, int height) : w(width), h(height), v(static_cast<std::size_t>(width) * height) {}
  double& at(int x, int y) { return v[static_cast<std::size_t>(y) * w + x]; }
  double at(int x, int y) const { return v[static_cast<std::size_t>(y) * w + x]; }
};

// ITU-R BT.601 luma, the weights the header specifies; not rounded.
Plane luminance(const Image& img) {
  Plane p(img.width(), img.height());
  for (int y = 0; y < img.height(); ++y) {
    for (int x = 0; x < img.width(); ++x) {
      const std::uint8_t* px = img.pixel(x, y);
      p.at(x, y) = 0.299 * px[0] + 0.587 * px[1] + 0.114 * px[2];
    }
  }
  return p;
}

// Normalised 1D Gaussian of `size` taps centred on the window, sigma 1.5.
// The 2D 11x11 window of Wang et al. is the outer product of two of these.
std::vector<double> gaussian(int size, double sigma) {
  std::vector<double> g(static_cast<std::size_t>(size));
  const double centre = (size - 1) / 2.0;
  double sum = 0.0;
  for (int i = 0; i < size; ++i) {
    const double d = i - centre;
    g[static_cast<std::size_t>(i)] = std::exp(-d * d / (2.0 * sigma * sigma));
    sum += g[static_cast<std::size_t>(i)];
  }
  for (double& t : g) t /= sum;
  return g;
}

// Separable 'valid' filtering: output (w-kx+1) x (h-ky+1), each output the
// window-weighted sum of the input under a window placed fully inside it.
Plane filterValid(const Plane& in, const std::vector<double>& gx, const std::vector<double>& gy) {
  const int kx = static_cast<int>(gx.size());
  const int ky = static_cast<int>(gy.size());
  Plane rows(in.w - kx + 1, in.h);
  for (int y = 0; y < in.h; ++y) {
    for (int x = 0; x < rows.w; ++x) {
      double s = 0.0;
      for (int k = 0; k < kx; ++k) s += gx[static_cast<std::size_t>(k)] * in.at(x + k, y);
      rows.at(x, y) = s;
    }
  }
  Plane out(rows.w, in.h - ky + 1);
  for (int y = 0; y < out.h; ++y) {
    for (int x = 0; x < out.w; ++x) {
      double s = 0.0;
      for (int k = 0; k < ky; ++k) s += gy[static_cast<std::size_t>(k)] * rows.at(x, y + k);
      out.at(x, y) = s;
    }
  }
  return out;
}

Plane product(const Plane& a, const Plane& b) {
  Plane p(a.w, a.h);
  for (std::size_t i = 0; i < p.v.size(); ++i) p.v[i] = a.v[i] * b.v[i];
  return p;
}

}  // namespace

double psnr(const Image& a, const Image& b) {
  requireComparable(a, b, "psnr");
  // PSNR = 10 log10(peak^2 / MSE), MSE over the R, G, B samples of every pixel.
  double sumSq = 0.0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      const std::uint8_t* pa = a.pixel(x, y);
      const std::uint8_t* pb = b.pixel(x, y);
      for (int c = 0; c < 3; ++c) {
        const double d = static_cast<double>(pa[c]) - static_cast<double>(pb[c]);
        sumSq += d * d;
      }
    }
  }
  if (sumSq == 0.0) return std::numeric_limits<double>::infinity();
  const double mse = sumSq / (3.0 * a.width() * a.height());
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

// Mean SSIM as in Wang, Bovik, Sheikh & Simoncelli 2004 (IEEE TIP 13(4)),
// eq. 13 with the authors' reference implementation's choices: local
// statistics under a normalised 11x11 Gaussian window (sigma 1.5), population
// (not sample) variances, and the mean taken over the 'valid' window
// positions only (no padding, so the border pixels carry less weight).
//
// Images narrower or lower than 11 pixels would have no valid position; there
// the window is shrunk to the image's width and/or height (still sigma 1.5,
// renormalised), which gives exactly one position along that axis.
double ssim(const Image& a, const Image& b) {
  requireComparable(a, b, "ssim");
  constexpr int kWindow = 11;
  constexpr double kSigma = 1.5;
  constexpr double kL = 255.0;
  constexpr double kC1 = (0.01 * kL) * (0.01 * kL);
  constexpr double kC2 = (0.03 * kL) * (0.03 * kL);

  const Plane x = luminance(a);
  const Plane y = luminance(b);
  const std::vector<double> gx = gaussian(std::min(kWindow, x.w), kSigma);
  const std::vector<double> gy = gaussian(std::min(kWindow, x.h), kSigma);

  const Plane muX = filterValid(x, gx, gy);
  const Plane muY = filterValid(y, gx, gy);
  const Plane xx = filterValid(product(x, x), gx, gy);
  const Plane yy = filterValid(product(y, y), gx, gy);
  const Plane xy = filterValid(product(x, y), gx, gy);

  double sum = 0.0;
  for (std::size_t i = 0; i < muX.v.size(); ++i) {
    const double mx = muX.v[i];
    const double my = muY.v[i];
    // sigma^2 = E[x^2] - E[x]^2 under the window weights.
    const double varX = xx.v[i] - mx * mx;
    const double varY = yy.v[i] - my * my;
    const double cov = xy.v[i] - mx * my;
    sum += ((2.0 * mx * my + kC1) * (2.0 * cov + kC2)) /
           ((mx * mx + my * my + kC1) * (varX + varY + kC2));
  }
  return sum / static_cast<double>(muX.v.size());
}

}  // namespace tessera
