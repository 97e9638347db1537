// A second volume over the anatomy, in the same ray march (docs/fusion.md,
// reference/FusedVolume.h for the CPU twin): at anatomy texture position p
// the fused volume is read at q = u_fusedFromAnatomy * p (both volumes'
// index -> world affines: another spacing, extent or orientation is
// resampled here), classified by its own table, and mixed over the
// anatomy's classified sample: colour mix(c, f, w), opacity
// max(a, 1 - (1 - w)^(ds / unit)), w = the fused opacity. Outside the fused
// box w = 0. With FUSION_LABELS the nearest voxel and the nearest of the
// table's entries (a label's own colour, nothing in between).
uniform highp sampler3D u_fused;  // normalised to its value range, R16F
uniform mat4 u_fusedFromAnatomy;
uniform sampler2D u_fusedTf;      // straight colour, uncorrected opacity
uniform float u_fusedTfSize;
uniform float u_fusedScale;  // window-normalised = clamp(stored * scale + bias, 0, 1)
uniform float u_fusedBias;
uniform float u_fusedOpacity;
uniform float u_fusedStepRatio;  // ds / the fused TF's opacity unit length
uniform vec3 u_fusedDims;

vec4 fusedColor(vec3 q) {
  if (any(lessThan(q, vec3(0.0))) || any(greaterThan(q, vec3(1.0)))) return vec4(0.0);
#ifdef FUSION_LABELS
  vec3 cell = clamp(floor(q * u_fusedDims), vec3(0.0), u_fusedDims - 1.0);
  float n = clamp(texelFetch(u_fused, ivec3(cell), 0).r * u_fusedScale + u_fusedBias, 0.0, 1.0);
  vec4 f = texelFetch(u_fusedTf, ivec2(int(floor(n * (u_fusedTfSize - 1.0) + 0.5)), 0), 0);
#else
  float n = clamp(texture(u_fused, q).r * u_fusedScale + u_fusedBias, 0.0, 1.0);
  float x = n * (u_fusedTfSize - 1.0);
  float x0 = min(floor(x), u_fusedTfSize - 2.0);
  vec4 f = mix(texelFetch(u_fusedTf, ivec2(int(x0), 0), 0),
               texelFetch(u_fusedTf, ivec2(int(x0) + 1, 0), 0), x - x0);
#endif
  return vec4(f.rgb, f.a * u_fusedOpacity);
}

// The anatomy's classified sample c (straight colour, opacity for one step)
// at p with the fused volume over it.
vec4 fuseSample(vec4 c, vec3 p) {
  vec4 f = fusedColor((u_fusedFromAnatomy * vec4(p, 1.0)).xyz);
  float a = 1.0 - pow(max(1.0 - f.a, 0.0), u_fusedStepRatio);
  return vec4(mix(c.rgb, f.rgb, f.a), max(c.a, a));
}
