#pragma once
// Pre-integrated classification (Engel, Kraus & Ertl 2001; Real-Time Volume
// Graphics ch. 4.5): the colour and opacity of a ray segment of length L on
// which the normalised value runs linearly from `front` to `back`, with the
// TF integrated over every value in between rather than looked up at the
// samples alone. The GPU ray caster reads an N x N table of it
// (render/PreIntegrationTable.h); the CPU reference evaluates it directly, in
// double precision, from the same integral functions.
//
// The TF's opacity a0(x) is per opacityUnitLength world units (TransferFunction.h),
// i.e. an extinction coefficient tau(x) = -ln(1 - a0(x) * scale) / unit per
// world unit. With the integral functions (cumulative sums over x)
//   T(x) = int_0^x tau,   K(x) = int_0^x tau c   (c = the TF's straight colour)
// a segment of length L from value f to value b has
//   alpha = 1 - exp(-L (T(b) - T(f)) / (b - f))     (exact for a linear field)
//   rgb   = (K(b) - K(f)) / (T(b) - T(f))            (the extinction-weighted mean colour)
// and is composited like a sample: premultiplied rgb * alpha. The colour
// neglects attenuation inside the segment (which part of it lies in front);
// that keeps one table valid for every length: a segment m times longer has
// alpha' = 1 - (1 - alpha)^m and the same colour, which is how adaptive steps
// use it. (Compositing each segment from 4 pieces, to first order the
// self-attenuation, changed ch2's PSNR against a 0.125-voxel reference by
// under 0.1 dB at steps 0.5-2 with the bench, ct-bone, mr-default and a
// spiky TF: the error of a large step is the field's curvature between the
// samples, not the colour's order within a segment.) For f == b it is exactly the post-classified
// sample: c(f) and 1 - (1 - a0)^(L / unit). Building an N x N table from T and K is O(N^2) (one
// subtraction per entry), so a TF edit rebuilds it in about a millisecond.
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "tessera/core/TransferFunction.h"

namespace tessera {

class PreIntegral {
 public:
  // T and K on `cells` equal cells of [0,1] (trapezoid rule on the continuous
  // TF, in double precision), between which they are linear.
  explicit PreIntegral(const TransferFunction& tf, double opacityScale = 1.0, int cells = 16384);

  // Extinction tau(x) per world unit (a0 capped just below 1: an opaque value
  // still transmits 1e-9 per unit length).
  double extinction(double x) const;
  // Straight colour (rgb) and opacity (a) of a segment of `length` world units.
  glm::dvec4 segment(double front, double back, double length) const;

  const TransferFunction& transferFunction() const { return tf_; }
  double opacityScale() const { return scale_; }

  // T(x) and K(x) (linear between cell boundaries).
  double integralT(double x) const;
  glm::dvec3 integralK(double x) const;
  // segment() from T and K at its ends (the table's O(1) per entry).
  glm::dvec4 fromIntegrals(double front, double back, double tFront, double tBack,
                           glm::dvec3 kFront, glm::dvec3 kBack, double length) const;

 private:
  TransferFunction tf_;
  double scale_;
  int cells_;
  std::vector<double> t_;      // T at cell boundaries
  std::vector<glm::dvec3> k_;  // K at cell boundaries
};

// The N x N table the GPU samples bilinearly: 4 floats per entry (straight
// rgb, alpha), entry (front i, back j) at index (j * N + i) * 4 holding
// segment(i / (N-1), j / (N-1), length). entries: 2..4096.
std::vector<float> bakePreIntegrationTable(const PreIntegral& integral, int entries, double length);

}  // namespace tessera
