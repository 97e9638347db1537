#pragma once
// An independent, slow evaluation of the FCC six-direction box spline for
// the tests: numerical convolution straight from the definition, sharing no
// code or derivation with lattice/FccBoxSpline.cpp (which uses tabulated
// polynomial pieces from an exact 3-D clipping script).
//
// With the directions split as A = {a1, a2, a3} = {(1,1,0), (1,-1,0), (1,0,1)}
// and B = {(1,0,-1), (0,1,1), (0,1,-1)} (|det B| = 2), the definition
// M_Xi(y) = integral over t in [0,1]^3 of M_B(y - t1 a1 - t2 a2 - t3 a3) dt,
// M_B = chi(B[0,1)^3) / 2, gives for K(x) = 2 M_Xi(x + c), c = sum(Xi) / 2:
//   K(x) = integral_0^1 S(x + c - t a1) dt,
//   S(z) = area{(t2, t3) in [0,1]^2 : B^-1 (z - t2 a2 - t3 a3) in [0,1]^3},
// a polygon area (two parameters clipped by six half-planes). S along the
// line is a piecewise quadratic in t whose breakpoints are the t of the
// vertices of the 3-D region, so Simpson's rule between all candidate
// breakpoints (every triple of the 12 bounding planes) integrates it exactly.
// The gradient comes from the box spline's derivative rule (de Boor, Hoellig
// & Riemenschneider 1993, ch. I): D_a K(x) = 2 (M_{Xi\a}(x + c) - M_{Xi\a}(x + c - a)),
// with M_{Xi\a} again a polygon area, for a = a1, a2, a3.
#include <functional>

#include <glm/vec3.hpp>

namespace tessera::lattice::test {

double slowKernel(glm::dvec3 x);
glm::dvec3 slowKernelGradient(glm::dvec3 x);

// sum over every FCC point j with |u - j|_inf < 3 of c(j) K(u - j).
double slowSpline(glm::dvec3 u, const std::function<double(glm::ivec3)>& c);
glm::dvec3 slowSplineGradient(glm::dvec3 u, const std::function<double(glm::ivec3)>& c);

}  // namespace tessera::lattice::test
