// Resolve pass of the slicing techniques (render/SliceAccumulator.h): reads
// the accumulated slices and composites the background behind them,
// out = C + (1 - A) * background, as the ray caster does at the end of a
// ray. With MODE_MIP the target holds (max n, -, -, hit) and the pixel is
// the TF colour of the maximum, opaque where a slice met the volume.
uniform sampler2D u_accumulation;
uniform vec2 u_viewport;
uniform vec4 u_background;  // premultiplied

void main() {
  vec4 acc = TEX2D(u_accumulation, gl_FragCoord.xy / u_viewport);
#ifdef MODE_MIP
  if (acc.a > 0.5) {
    acc = vec4(classify(acc.r).rgb, 1.0);
  } else {
    acc = vec4(0.0);
  }
#endif
  FRAG_COLOR = vec4(acc.rgb + (1.0 - acc.a) * u_background.rgb,
                    acc.a + (1.0 - acc.a) * u_background.a);
}
