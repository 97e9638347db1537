// Roofline kernels (render/Roofline.h): ROOFLINE_FETCHES fetches per
// fragment of kind ROOFLINE_KERNEL (0 independent 3D, 1 dependent 3D, 2 TF
// lookup, 3 3D then TF, 4 3D then unfiltered TF, 5 3D then TF in the
// shader), summed so the compiler must keep every fetch.
uniform highp sampler3D u_volume;
uniform sampler2D u_tf;
uniform sampler2D u_tfNearest;
uniform vec2 u_viewport;
uniform vec3 u_delta;  // one step of the walk in texture coordinates

void main() {
  vec2 uv = gl_FragCoord.xy / u_viewport;
  // Neighbouring fragments walk neighbouring texels, as neighbouring rays do.
  vec3 p = vec3(uv, 0.0);
  vec4 acc = vec4(0.0);
  for (int k = 0; k < ROOFLINE_FETCHES; ++k) {
#if ROOFLINE_KERNEL == 0
    acc.r += texture(u_volume, p + float(k) * u_delta).r;
#elif ROOFLINE_KERNEL == 1
    float v = texture(u_volume, p).r;
    acc.r += v;
    p += u_delta * (1.0 + 0.001 * v);
#elif ROOFLINE_KERNEL == 2
    acc += texture(u_tf, vec2(fract(uv.x + float(k) * 0.618034), 0.5));
#elif ROOFLINE_KERNEL == 3
    float v = texture(u_volume, p + float(k) * u_delta).r;
    acc += texture(u_tf, vec2(v, 0.5));
#elif ROOFLINE_KERNEL == 4
    float v = texture(u_volume, p + float(k) * u_delta).r;
    acc += texture(u_tfNearest, vec2(v, 0.5));
#else
    // The `bench` preset: grey ramp, opacity 0 up to 0.2 then rising to 0.2.
    float v = texture(u_volume, p + float(k) * u_delta).r;
    acc += vec4(v, v, v, 0.2 * clamp((v - 0.2) * 1.25, 0.0, 1.0));
#endif
  }
  FRAG_COLOR = acc;
}
