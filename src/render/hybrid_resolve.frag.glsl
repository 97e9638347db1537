// Low-resolution resolve of the hybrid compositor: (volume colour over
// black, opacity estimate) per offscreen pixel, by one of the methods of
// Moser & Weiskopf 2008 (section 4), chosen by a define.
uniform sampler2D u_volume;  // the technique's render (over black, or transparent black)
uniform sampler2D u_white;   // METHOD_TWO_PASS: the same render over white
uniform vec2 u_size;

void main() {
  vec2 uv = gl_FragCoord.xy / u_size;
  vec4 c = TEX2D(u_volume, uv);
#if defined(METHOD_COPY)
  FRAG_COLOR = c;
#elif defined(METHOD_ALPHA)
  FRAG_COLOR = c;
#elif defined(METHOD_TWO_PASS)
  // C_white - C_black = 1 - a in every channel; the mean damps rounding.
  vec3 w = TEX2D(u_white, uv).rgb;
  float a = 1.0 - dot(w - c.rgb, vec3(1.0 / 3.0));
  FRAG_COLOR = vec4(c.rgb, clamp(a, 0.0, 1.0));
#elif defined(METHOD_LUMA_AVG)
  FRAG_COLOR = vec4(c.rgb, dot(c.rgb, vec3(1.0 / 3.0)));
#elif defined(METHOD_LUMA_601)
  FRAG_COLOR = vec4(c.rgb, dot(c.rgb, vec3(0.3, 0.59, 0.11)));
#endif
}
