// Primary rays and the volume box, mirroring Camera::ndcRay and the CPU
// reference (reference/ReferenceRaycaster.cpp) so images compare pixel by pixel.
uniform vec3 u_eye;
uniform vec3 u_right;
uniform vec3 u_up;
uniform vec3 u_forward;
uniform float u_tanHalfFov;
uniform float u_orthoHalfHeight;
uniform float u_aspect;
uniform int u_ortho;
uniform vec2 u_viewport;
uniform vec3 u_extent;  // world size of the volume box, centred at the origin

void cameraRay(vec2 ndc, out vec3 origin, out vec3 dir) {
  if (u_ortho == 1) {
    origin = u_eye + u_right * (ndc.x * u_orthoHalfHeight * u_aspect) +
             u_up * (ndc.y * u_orthoHalfHeight);
    dir = u_forward;
  } else {
    origin = u_eye;
    dir = normalize(u_forward + u_right * (ndc.x * u_tanHalfFov * u_aspect) +
                    u_up * (ndc.y * u_tanHalfFov));
  }
}

// Ray/slab intersection with the unit cube in texture space; returns
// (tNear, tFar) in the ray's parameter (world length), tNear > tFar if missed.
vec2 intersectUnitBox(vec3 o, vec3 invD) {
  vec3 a = (vec3(0.0) - o) * invD;
  vec3 b = (vec3(1.0) - o) * invD;
  vec3 lo = min(a, b);
  vec3 hi = max(a, b);
  return vec2(max(max(lo.x, lo.y), lo.z), min(min(hi.x, hi.y), hi.z));
}

// 1/d with zero components replaced by a huge value of the right sign, so the
// slab test and block exits never divide by zero.
vec3 safeInverse(vec3 d) {
  vec3 s = vec3(d.x >= 0.0 ? 1.0 : -1.0, d.y >= 0.0 ? 1.0 : -1.0, d.z >= 0.0 ? 1.0 : -1.0);
  return s / max(abs(d), vec3(1e-20));
}

// Offset of the first sample, in [0,1): an 8x8 ordered-dither (Bayer)
// pattern over the pixel grid, the twin of tessera::jitterOffset
// (core/RenderSettings.h). Small integers only, so float maths is exact in
// GLSL ES 1.00 and 3.00 alike. x, y: pixel column and row from the top.
float jitterOffset(float x, float y) {
  float v = 0.0;
  float scale = 16.0;
  float bit = 1.0;
  for (int i = 0; i < 3; i++) {
    float xi = mod(floor(x / bit), 2.0);
    float yi = mod(floor(y / bit), 2.0);
    v += (2.0 * abs(xi - yi) + yi) * scale;
    scale *= 0.25;
    bit *= 2.0;
  }
  return (v + 0.5) / 64.0;
}
