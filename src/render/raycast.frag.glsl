// Single-pass ray caster (GLSL ES 3.00): ray-box intersection here, no proxy
// pass; samples at t0 + (k + j) * ds; front-to-back compositing of
// premultiplied colour (Noguera et al. 2012, eq. 1) with early termination;
// MIP with MODE_MIP. With EMPTY_SPACE_SKIPPING, blocks whose every possible
// sample is transparent (or cannot raise the maximum) are jumped over
// without changing which samples are taken.

uniform float u_step;      // world units
uniform int u_maxSteps;
uniform float u_ert;       // early termination threshold
uniform int u_jitter;
uniform vec4 u_background; // premultiplied

#ifdef EMPTY_SPACE_SKIPPING
uniform highp sampler3D u_blocks;  // RG8: r = any opacity, g = ceil(max normalised value)
uniform vec3 u_blocksPerUnit;      // blocks per texture-space unit = dims / blockSize
uniform vec3 u_blockCount;
#endif

void main() {
  vec2 ndc = gl_FragCoord.xy / u_viewport * 2.0 - 1.0;
  vec3 ro;
  vec3 rd;
  cameraRay(ndc, ro, rd);
  vec3 to = ro / u_extent + 0.5;  // texture space, t stays in world units
  vec3 td = rd / u_extent;
  vec3 invTd = safeInverse(td);
  vec2 range = intersectUnitBox(to, invTd);
  float t0 = max(range.x, 0.0);
  float t1 = range.y;

  vec4 acc = vec4(0.0);
  float maxValue = -1.0;
  if (t0 < t1) {
    float j = 0.5;
    if (u_jitter == 1) {
      j = jitterOffset(uint(gl_FragCoord.x), uint(u_viewport.y - gl_FragCoord.y));
    }
    int k = 0;
    while (k < u_maxSteps) {
      float t = t0 + (float(k) + j) * u_step;
      if (t >= t1) break;
      vec3 p = to + t * td;
#ifdef EMPTY_SPACE_SKIPPING
      vec3 cell = clamp(floor(p * u_blocksPerUnit), vec3(0.0), u_blockCount - 1.0);
      vec2 block = texelFetch(u_blocks, ivec3(cell), 0).rg;
#ifdef MODE_MIP
      bool empty = block.g <= maxValue;
#else
      bool empty = block.r < 0.5;
#endif
      if (empty) {
        vec3 exitFace = (cell + step(0.0, td)) / u_blocksPerUnit;
        vec3 tb = (exitFace - to) * invTd;
        float tExit = min(min(tb.x, tb.y), tb.z);
        k = max(int(ceil((tExit - t0) / u_step - j)), k + 1);
        continue;
      }
#endif
      float n = normalizedValue(sampleVolume(p));
#ifdef MODE_MIP
      maxValue = max(maxValue, n);
#else
      vec4 c = classify(n);
      acc.rgb += (1.0 - acc.a) * c.a * c.rgb;
      acc.a += (1.0 - acc.a) * c.a;
      if (acc.a >= u_ert) break;
#endif
      k++;
    }
  }
#ifdef MODE_MIP
  if (maxValue >= 0.0) {
    // MIP shows the TF colour of the maximum, opaque (the classic MIP look:
    // with the grey preset the pixel is the maximum intensity).
    acc = vec4(classify(maxValue).rgb, 1.0);
  }
#endif
  FRAG_COLOR = vec4(acc.rgb + (1.0 - acc.a) * u_background.rgb, acc.a + (1.0 - acc.a) * u_background.a);
}
