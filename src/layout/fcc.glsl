// sampleVolume for FccLayout (GLSL ES 3.00 only): the six-direction box
// spline of an FCC lattice (lattice/FccBoxSpline.h, whose CPU evaluator this
// mirrors step by step) from its x-packed texels (lattice/FccVolume.h).
// Kim, "GPU isosurface raycasting of FCC datasets", Graphical Models 75(2),
// 2013: the knot planes cut each unit cube into five tetrahedra; an odd cube
// is the point reflection of an even one and two-axis reflections map the
// four corner tetrahedra onto the one at the origin, so two reference pieces
// (layout/fcc_pieces.glsl, generated) with 16 lattice points each give every
// value. Uniform control flow per piece; no tables in memory.
uniform highp sampler3D u_layoutFcc;  // NEAREST; packed texels, or cubes with FCC_CUBES
uniform vec3 u_layoutFccGrid;         // grid dims D of the lattice

#ifdef FCC_CUBES
// Cube storage (FccLayout::Storage::Cubes): texel q + 2 holds, in channel
// o.x + 2 o.y, the value of the FCC corner q + o of the unit cube at q (o.z
// from the parity), boundary rule applied, for q in [-2, D]^3: the cube of
// reference offset q under the piece's reflection s and base b, its
// channels reordered so that the reference channel reads the right corner
// (a flip of x swaps the channel's bit 0, of y its bit 1).
vec4 fccCube(ivec3 b, ivec3 s, ivec3 q) {
#ifdef FCC_ARITHMETIC_ONLY
  vec3 o = vec3(b + s * q);
  return vec4(o.x, o.y, o.z, o.x - o.y) * 0.01;
#else
  vec4 t = texelFetch(u_layoutFcc, b + s * q + (s - 1) / 2 + 2, 0);
  t = s.x < 0 ? t.grab : t;
  return s.y < 0 ? t.barg : t;
#endif
}
#endif

// Lattice point q under the boundary rule: clamp to the grid, then texel
// (x >> 1, y, z) of the packing.
float fccPoint(ivec3 q) {
#ifdef FCC_ARITHMETIC_ONLY
  // The benchmark's cost split (FccLayout::Evaluation::ArithmeticOnly): a
  // value that depends on q, but no fetch.
  return float(q.x - q.y + q.z) * 0.01;
#else
  ivec3 c = clamp(q, ivec3(0), ivec3(u_layoutFccGrid) - 1);
  return texelFetch(u_layoutFcc, ivec3(c.x >> 1, c.y, c.z), 0).r;
#endif
}

float fccCorner(ivec3 b, ivec3 s, vec3 l);
float fccCentral(ivec3 b, ivec3 s, vec3 l);

float sampleVolume(vec3 p) {
  vec3 u = p * u_layoutFccGrid - 0.5;
  vec3 o = floor(u);
  vec3 v = u - o;
  ivec3 io = ivec3(o);
  bool odd = ((io.x + io.y + io.z) & 1) != 0;
  vec3 w = odd ? 1.0 - v : v;
  // Which two-axis reflection carries w's corner tetrahedron to the origin's
  // (none for the origin's own), or the central tetrahedron.
  bvec3 reflect = bvec3(false);
  bool central = false;
  if (w.x + w.y + w.z > 1.0) {
    if (w.x + w.y - w.z >= 1.0) {
      reflect = bvec3(true, true, false);
    } else if (w.x - w.y + w.z >= 1.0) {
      reflect = bvec3(true, false, true);
    } else if (-w.x + w.y + w.z >= 1.0) {
      reflect = bvec3(false, true, true);
    } else {
      central = true;
    }
  }
  // Both reflections together: lattice point = base + sign * offset.
  bvec3 flip = notEqual(bvec3(odd), reflect);
  ivec3 f = ivec3(flip);
  ivec3 base = io + f;
  ivec3 sgn = 1 - 2 * f;
  vec3 local = mix(v, 1.0 - v, vec3(flip));
  return central ? fccCentral(base, sgn, local) : fccCorner(base, sgn, local);
}
