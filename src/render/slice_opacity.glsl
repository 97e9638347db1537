// Opacity of a premultiplied sample that stands for `ratio` times the
// distance its table was baked for: a' = 1 - (1 - a)^ratio (DESIGN.md,
// Rendering semantics), colour scaled with it so it stays premultiplied.
vec4 correctOpacity(vec4 premultiplied, float ratio) {
  float a = 1.0 - pow(max(1.0 - premultiplied.a, 0.0), ratio);
  return vec4(premultiplied.rgb * (a / max(premultiplied.a, 1e-6)), a);
}

// A slab's premultiplied colour before its one blend into an 8-bit target,
// which rounds each blend: a slab's small contribution would round the same
// way in every slab of a uniform region. An offset of -0.5..0.5 of a level,
// interleaved gradient noise over the pixel shifted per slab (Jimenez 2014),
// makes the rounding unbiased on average. Empty fragments stay exactly 0
// (negative values round to 0 as well).
vec4 ditherTo8Bits(vec4 acc, float slab) {
  vec2 noisePixel = gl_FragCoord.xy + 5.588238 * slab;
  float noise = fract(52.9829189 * fract(dot(noisePixel, vec2(0.06711056, 0.00583715))));
  return acc.a > 0.0 ? max(acc + (noise - 0.5) / 255.0, 0.0) : acc;
}
