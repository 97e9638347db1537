// Opacity of a premultiplied sample that stands for `ratio` times the
// distance its table was baked for: a' = 1 - (1 - a)^ratio (DESIGN.md,
// Rendering semantics), colour scaled with it so it stays premultiplied.
vec4 correctOpacity(vec4 premultiplied, float ratio) {
  float a = 1.0 - pow(max(1.0 - premultiplied.a, 0.0), ratio);
  return vec4(premultiplied.rgb * (a / max(premultiplied.a, 1e-6)), a);
}
