// LayoutProbe: one fragment per position, writes sampleVolume(position)
// (with TESSERA_PROBE_GRADIENT: sampleVolumeGradient in rgb, the value in a).
#ifdef TESSERA_PROBE_RGBA8
// RGBA8 target (ES 2): v in [0,1] as hi = floor(255 v) / 255 in R and
// lo = fract(255 v) in G; LayoutProbe decodes (255 hi + lo) / 255, exact to
// half of 1/65025. A = 1 marks a written pixel. Positions come from
// probe.vert.glsl (no texelFetch in GLSL ES 1.00).
#if TESSERA_GLSL == 300
in vec3 v_probe;
#else
varying vec3 v_probe;
#endif

void main() {
  float v = clamp(sampleVolume(v_probe), 0.0, 1.0) * 255.0;
  float hi = floor(v);
  FRAG_COLOR = vec4(hi / 255.0, v - hi, 0.0, 1.0);
}
#else
uniform highp sampler2D u_positions;  // RGB32F, one position per texel

void main() {
  vec3 p = texelFetch(u_positions, ivec2(gl_FragCoord.xy), 0).xyz;
#ifdef TESSERA_PROBE_GRADIENT
  FRAG_COLOR = vec4(sampleVolumeGradient(p), sampleVolume(p));
#else
  FRAG_COLOR = vec4(sampleVolume(p), 0.0, 0.0, 1.0);
#endif
}
#endif
