// Single-pass ray caster for GLSL ES 1.00 and 3.00: the volume only through
// the layout's sampleVolume() (render/sample.glsl: classifiedSample,
// fieldValue); ray-box intersection here, no proxy pass; samples at
// t0 + (k + j) * ds; front-to-back compositing of premultiplied colour
// (Noguera et al. 2012, eq. 1) with early termination; MIP, MinIP and the
// average with MODE_MIP, MODE_MINIP, MODE_AVERAGE; with CLIPPING the samples
// that clip planes or the crop box reject are dropped (render/clipping.glsl).
// The loop bound MAX_STEPS is a compile-time constant, as GLSL ES 1.00
// requires (Appendix A).
// With EMPTY_SPACE_SKIPPING, blocks whose every possible sample is
// transparent (or cannot raise the maximum) are jumped over without changing
// which samples are taken, so the image is the same as without skipping.

uniform float u_step;       // world units
uniform float u_maxSteps;   // the user's cap, <= MAX_STEPS
uniform float u_ert;        // early termination threshold
uniform float u_jitter;     // 1.0: dithered first sample
uniform vec4 u_background;  // premultiplied

#ifdef EMPTY_SPACE_SKIPPING
// The block grid: r = 1 where the TF gives some sample in the block opacity,
// g = the largest normalised value in the block, rounded up.
uniform vec3 u_blocksPerUnit;  // blocks per texture-space unit = dims / blockSize
uniform vec3 u_blockCount;
#if TESSERA_GLSL == 300
uniform highp sampler3D u_blocks;

vec4 blockAt(vec3 cell) {
  return texelFetch(u_blocks, ivec3(cell), 0);
}
#else
// Without 3D textures: the grid's z-slices side by side in a 2D texture.
uniform sampler2D u_blocks;
uniform float u_blockTilesX;  // z-slices of the grid per mosaic row
uniform vec2 u_blockTexSize;

vec4 blockAt(vec3 cell) {
  float tileX = mod(cell.z, u_blockTilesX);
  float tileY = floor(cell.z / u_blockTilesX);
  vec2 texel = vec2(tileX * u_blockCount.x + cell.x, tileY * u_blockCount.y + cell.y) + 0.5;
  return TEX2D(u_blocks, texel / u_blockTexSize);
}
#endif
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
  float minValue = 2.0;  // MinIP
  float sumValue = 0.0;  // average
  float kept = 0.0;      // samples the projections kept
  if (t0 < t1) {
    float j = 0.5;
    if (u_jitter > 0.5) {
      j = jitterOffset(floor(gl_FragCoord.x), u_viewport.y - 1.0 - floor(gl_FragCoord.y));
    }
    float k = 0.0;  // sample index; a float so GLSL ES 1.00 needs no integer maths
#ifdef CLIPPING
    // March only through the crop box, from the box-aligned sample at or just
    // before its entry (clipKeeps drops any sample outside): no sample moves.
    vec3 cropLo = min((u_cropMin - to) * invTd, (u_cropMax - to) * invTd);
    vec3 cropHi = max((u_cropMin - to) * invTd, (u_cropMax - to) * invTd);
    vec2 crop =
        vec2(max(max(cropLo.x, cropLo.y), cropLo.z), min(min(cropHi.x, cropHi.y), cropHi.z));
    k = max(0.0, floor((crop.x - t0) / u_step - j));
    t1 = min(t1, crop.y + 0.5 * u_step);
#endif
#ifdef EMPTY_SPACE_SKIPPING
    // The block grid is read once per block the ray enters, not per sample:
    // samples before tBlockExit lie in the occupied block read last (one
    // that float rounding puts just past the face is taken too, harmlessly:
    // a skippable block's samples add nothing).
    float tBlockExit = -1.0;
#endif
    for (int i = 0; i < MAX_STEPS; i++) {
      if (k >= u_maxSteps) break;
      float t = t0 + (k + j) * u_step;
      if (t >= t1) break;
      vec3 p = to + t * td;
#ifdef EMPTY_SPACE_SKIPPING
      if (t >= tBlockExit) {
        vec3 cell = clamp(floor(p * u_blocksPerUnit), vec3(0.0), u_blockCount - 1.0);
        vec4 block = blockAt(cell);
#ifdef MODE_MIP
        bool empty = block.g <= maxValue;
#else
        bool empty = block.r < 0.5;
#endif
        vec3 exitFace = (cell + step(0.0, td)) / u_blocksPerUnit;
        vec3 tb = (exitFace - to) * invTd;
        float tExit = min(min(tb.x, tb.y), tb.z);
        if (empty) {
          // Jump to the first sample at or past the block's exit face.
          k = max(ceil((tExit - t0) / u_step - j), k + 1.0);
          continue;
        }
        tBlockExit = tExit;
      }
#endif
#ifdef CLIPPING
      if (!clipKeeps(p)) {
        k += 1.0;
        continue;
      }
#endif
#if defined(MODE_MIP)
      maxValue = max(maxValue, normalizedValue(fieldValue(p)));
#elif defined(MODE_MINIP)
      minValue = min(minValue, normalizedValue(fieldValue(p)));
      kept += 1.0;
#elif defined(MODE_AVERAGE)
      sumValue += normalizedValue(fieldValue(p));
      kept += 1.0;
#else
      compositeFrontToBack(acc, classifiedSample(p));
      if (acc.a >= u_ert) break;
#endif
      k += 1.0;
    }
  }
#ifdef MODE_MIP
  if (maxValue >= 0.0) {
    // MIP shows the TF colour of the maximum, opaque (the classic MIP look:
    // with the grey preset the pixel is the maximum intensity).
    acc = vec4(classify(maxValue).rgb, 1.0);
  }
#elif defined(MODE_MINIP)
  if (kept > 0.0) acc = vec4(classify(minValue).rgb, 1.0);
#elif defined(MODE_AVERAGE)
  if (kept > 0.0) acc = vec4(classify(sumValue / kept).rgb, 1.0);
#endif
  FRAG_COLOR = overBackground(acc, u_background);
}
