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
// With PREINTEGRATED the composite mode classifies each segment between two
// samples by its front and back values (classifiedSegment); with
// ADAPTIVE_SAMPLING the block grid also holds a step multiplier m per block
// and the ray takes every m-th sample of its lattice there (the walk of
// reference/AdaptiveSteps.h, which the CPU reference follows too).

uniform float u_step;       // world units
uniform float u_maxSteps;   // the user's cap, <= MAX_STEPS
uniform float u_ert;        // early termination threshold
uniform float u_jitter;     // 1.0: dithered first sample
uniform vec4 u_background;  // premultiplied

#ifdef EMPTY_SPACE_SKIPPING
// The block grid: r = 0 where the TF gives some sample in the block opacity,
// otherwise the chessboard distance d to the nearest such block (/255; the
// cube of blocks d - 1 around it is empty too), g = the largest normalised
// value in the block, rounded up; with
// ADAPTIVE_SAMPLING b = the block's step code and a = the smallest code of
// its six face neighbours (AdaptiveSteps.h).
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

// The ray's block-face geometry, fixed per ray so that the march divides by
// nothing (a SIMD rasteriser runs the block code on every iteration): the
// parameter of face plane f (in blocks) along each axis is f * faceScale +
// faceBias; the far faces of a block lie at cell + faceSide; base sample
// index = t * invStep - sampleBias.
struct RayBlocks {
  vec3 faceScale;
  vec3 faceBias;
  vec3 faceSide;
  vec3 outward;  // sign(td): which way a radius widens the exit face
  float invStep;
  float sampleBias;
};

RayBlocks rayBlocks(vec3 to, vec3 td, vec3 invTd, float t0, float j) {
  RayBlocks r;
  r.faceScale = invTd / u_blocksPerUnit;
  r.faceBias = -to * invTd;
  r.faceSide = step(0.0, td);
  r.outward = sign(td);
  r.invStep = 1.0 / u_step;
  r.sampleBias = t0 * r.invStep + j;
  return r;
}

// The ray parameter where it leaves the cube of blocks within chessboard
// distance `radius` of block `cell`, and where it leaves the block it enters
// there (across the face it leaves by, the first axis on a tie, as
// AdaptiveSteps.cpp's StepGrid::exit): x and y of the result.
vec2 exitT(vec3 cell, float radius, RayBlocks r) {
  vec3 tb = (cell + r.faceSide + r.outward * radius) * r.faceScale + r.faceBias;
  float tExit = min(min(tb.x, tb.y), tb.z);
  vec3 axis = tExit == tb.x ? vec3(1.0, 0.0, 0.0)
                            : (tExit == tb.y ? vec3(0.0, 1.0, 0.0) : vec3(0.0, 0.0, 1.0));
  vec3 tAhead = tb + axis * abs(r.faceScale);
  return vec2(tExit, min(min(tAhead.x, tAhead.y), tAhead.z));
}

// The first base sample at or past parameter tExit (AdaptiveSteps.h:
// exitSample).
float exitSample(float tExit, RayBlocks r, float k) {
  return max(ceil(tExit * r.invStep - r.sampleBias), k + 1.0);
}

#ifdef ADAPTIVE_SAMPLING
uniform float u_log2MaxMultiplier;

// The multipliers for the step codes in `codes` (AdaptiveSteps.h: 64 +
// floor(8 log2 s), s a step allowance; x the block's own, y the bound on its
// neighbours') behind accumulated opacity alpha, given as log2T = log2(1 -
// alpha): 2^floor(log2(s / (1 - alpha))), 1..2^u_log2MaxMultiplier, with 1 -
// alpha at least 1e-6 (log2: -19.93). Integer maths on floats, rounded, so
// that the lattice arithmetic stays exact; on ES 3 the power of two as an
// integer shift (software rasterisers pay for every exp2).
vec2 stepMultipliers(vec2 codes, float log2T) {
  vec2 code = floor(codes * 255.0 + 0.5);
  vec2 e = clamp(floor((code - 64.0) * 0.125 - max(log2T, -19.931569)), 0.0,
                 u_log2MaxMultiplier);
#if TESSERA_GLSL == 300
  return vec2(float(1 << int(e.x)), float(1 << int(e.y)));
#else
  return floor(exp2(e) + 0.5);
#endif
}

float nextMultiple(float k, float m) {
  return (floor(k / m) + 1.0) * m;
}

// The next sample after k in a block with multiplier m whose exit sample is
// kExit, with the block ahead's multiplier mAhead (0: none or empty) and exit
// sample kExitAhead (AdaptiveSteps.h: nextAdaptiveSample): the next multiple
// of m inside the block; across its face on the lattice of min(m, mAhead),
// ending inside the block ahead; without one, a pre-integrated ray crosses
// the face in one base step from kExit - 1.
float nextSample(float k, float m, float kExit, float mAhead, float kExitAhead) {
#ifdef PREINTEGRATED
  float last = kExit - 1.0;
  float end = kExitAhead - 1.0;
#else
  float last = kExit;
  float end = kExitAhead;
#endif
  float aligned = nextMultiple(k, m);
  if (aligned <= last) return aligned;
  if (mAhead <= 0.0) return max(k + 1.0, last);
  return max(k + 1.0, min(nextMultiple(k, min(m, mAhead)), end));
}
#endif
#endif

#ifdef EMPTY_SPACE_SKIPPING
// The ray enters the block holding p at sample k: reads it and sets the
// first sample at or past its exit face (where an empty block is left for,
// and where adaptive steps end unless the block ahead lets them cross) and,
// with ADAPTIVE_SAMPLING, the exit sample of the block ahead.
void enterBlock(vec3 p, float k, RayBlocks rb, out vec4 block, out float blockExit,
                out float aheadExit) {
  vec3 cell = clamp(floor(p * u_blocksPerUnit), vec3(0.0), u_blockCount - 1.0);
  block = blockAt(cell);
#ifdef MODE_MIP
  float radius = 0.0;
#else
  // An empty block is left with the cube of empty blocks around it.
  float radius = max(floor(block.r * 255.0 + 0.5) - 1.0, 0.0);
#endif
  vec2 exits = exitT(cell, radius, rb);
  blockExit = exitSample(exits.x, rb, k);
#ifdef ADAPTIVE_SAMPLING
  aheadExit = exitSample(exits.y, rb, k);
#else
  aheadExit = -1.0;
#endif
}
#endif

// Whether clipping keeps the sample at p.
bool sampleKept(vec3 p) {
#ifdef CLIPPING
  return clipKeeps(p);
#else
  return true;
#endif
}

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
#ifdef LOG_TRANSMITTANCE
  float logT = 0.0;  // log2(1 - acc.a)
#endif
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
#ifdef PREINTEGRATED
    // Segments run between samples: on the lattice shifted back half a step,
    // one sample more, segment k-1..k covers exactly the stretch
    // [t0 + (k + j - 1) ds, t0 + (k + j) ds] that post-classified sample k - 1
    // stands for, from the ray's entry to past its exit.
    j -= 0.5;
    t1 += 0.5 * u_step;
#endif
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
#ifdef PREINTEGRATED
    float frontN = 0.0;      // the segment's front sample: value and index
    float frontK = -1.0;     // < 0: none (the ray starts a new segment)
    bool lazyFront = false;  // after an empty block: the front is sample k - 1
#endif
#ifdef EMPTY_SPACE_SKIPPING
    // The block grid is read once per block the ray enters, not per sample
    // (SwiftShader, in browsers, pays for every fetch): samples before
    // blockExit lie in the block read last.
    float blockExit = -1.0;
    vec4 block = vec4(0.0);
    RayBlocks rb = rayBlocks(to, td, invTd, t0, j);
    float aheadExit = -1.0;  // the exit sample of the next block along the ray
#endif
#ifdef LAYOUT_BRICK_WALK
    // The brick walk (ImageVis3D's and Gigavoxels' brick marching): the outer
    // loop enters one brick cell of the layout per iteration and reads its
    // page once (layoutEnterCell); the inner loop takes the samples before
    // the ray leaves the cell, sampling that brick directly
    // (sampleVolumeInCell, through fieldValue). The same samples, in the
    // same order, as one loop; on a SIMD rasteriser (llvmpipe runs both sides
    // of every branch for the whole group) the page read leaves the
    // per-sample loop.
    vec3 walkScale = invTd / layoutWalkCellsPerUnit();
    vec3 walkBias = -to * invTd;
    vec3 walkSide = step(0.0, td);
    float walkInvStep = 1.0 / u_step;
    float walkSampleBias = t0 * walkInvStep + j;
    // The first sample index the loop below would stop at (k >= u_maxSteps
    // or t >= t1), settled once with the loop's own float expression, so
    // the inner loop tests one bound a sample: the cell's exit, capped here.
    float walkEnd = ceil((t1 - t0) * walkInvStep - j);
    if (t0 + (walkEnd - 1.0 + j) * u_step >= t1) walkEnd -= 1.0;
    if (t0 + (walkEnd + j) * u_step < t1) walkEnd += 1.0;
    walkEnd = min(max(walkEnd, 0.0), u_maxSteps);
    for (int w = 0; w < MAX_STEPS; w++) {
      if (k >= walkEnd) break;
      float tw = t0 + (k + j) * u_step;
#if !defined(MODE_MIP) && !defined(MODE_MINIP) && !defined(MODE_AVERAGE)
      if (acc.a >= u_ert) break;
#endif
      vec3 walkCell = layoutEnterCell(to + tw * td);
      // The first sample at or past the cell's exit face.
      vec3 tb = (walkCell + walkSide) * walkScale + walkBias;
      float cellExit = min(
          max(ceil(min(min(tb.x, tb.y), tb.z) * walkInvStep - walkSampleBias), k + 1.0), walkEnd);
#if !defined(MODE_MIP) && !defined(MODE_MINIP) && !defined(MODE_AVERAGE) && !defined(FUSION) && !defined(CHANNELS)
      // A cell the TF makes transparent adds nothing: crossed in one step.
      if (layoutCellTransparent() > 0.5) {
        k = cellExit;
        continue;
      }
#endif
#endif
    for (int i = 0; i < MAX_STEPS; i++) {
#ifdef LAYOUT_BRICK_WALK
      if (k >= cellExit) break;  // also past the ray's end (walkEnd)
      float t = t0 + (k + j) * u_step;
#else
      if (k >= u_maxSteps) break;
      float t = t0 + (k + j) * u_step;
      if (t >= t1) break;
#endif
      vec3 p = to + t * td;
      float kNext = k + 1.0;
      bool empty = false;
#ifdef EMPTY_SPACE_SKIPPING
      if (k >= blockExit) {
        enterBlock(p, k, rb, block, blockExit, aheadExit);
      }
#ifdef MODE_MIP
      empty = block.g <= maxValue;
#else
      empty = block.r > 0.5 / 255.0;
#endif
      float kExit = blockExit;
#ifdef ADAPTIVE_SAMPLING
#if defined(OPACITY_GROWTH) && defined(LOG_TRANSMITTANCE)
      float grownBy = logT;  // log2(1 - acc.a), summed as the ray composites
#elif defined(OPACITY_GROWTH)
      float grownBy = log2(max(1.0 - acc.a, 1e-6));
#else
      float grownBy = 0.0;
#endif
      vec2 ms = stepMultipliers(block.ba, grownBy);
      float m = ms.x;
      // Whichever face neighbour the ray enters, its code is at least the
      // smallest of the six (a; 0 when one is empty or outside the grid).
      float mAhead = block.a < 0.5 / 255.0 ? 0.0 : ms.y;
      if (m > 1.0) kNext = nextSample(k, m, kExit, mAhead, aheadExit);
#endif
      if (empty) kNext = kExit;
#ifdef PREINTEGRATED
      // An empty block still ends the segment that enters it (below); with
      // no segment open there is nothing to read.
      if (empty && frontK < 0.0) {
        lazyFront = true;
        k = kNext;
        continue;
      }
#else
      if (empty) {
        k = kNext;
        continue;
      }
#endif
#endif
#if defined(PREINTEGRATED) && !defined(MODE_MIP) && !defined(MODE_MINIP) && !defined(MODE_AVERAGE)
      // One volume and one table fetch per iteration, whatever happens (a
      // SIMD rasteriser such as llvmpipe runs every branch of the body for
      // the whole group): after an empty block, an iteration reads the front
      // at k - 1 and stays at k; clipping drops the segments it touches.
      bool frontOnly = lazyFront && frontK < 0.0 && sampleKept(p);
      vec3 q = frontOnly ? p - u_step * td : p;
      bool keepQ = sampleKept(q);
      float n = normalizedValue(segmentValue(q));
      float tMid = t0 + (0.5 * (frontK + k) + j) * u_step;
      vec4 c = classifiedSegment(frontN, n, k - frontK, to + tMid * td);
      bool composites = !frontOnly && keepQ && frontK >= 0.0;
#ifdef LOG_TRANSMITTANCE
      // The segment stands for k - frontK base steps (see the post-classified
      // case below).
      float stretchLog2T = (k - frontK) * c.a;
      c.a = 1.0 - exp2(stretchLog2T);
      if (composites) logT += stretchLog2T;
#endif
      if (composites) compositeFrontToBack(acc, c);
      frontN = n;
      if (frontOnly) {
        frontK = keepQ ? k - 1.0 : -1.0;
        kNext = k;
      } else {
        frontK = keepQ && !empty ? k : -1.0;
      }
      lazyFront = !frontOnly && empty;
      if (acc.a >= u_ert) break;
#else
#ifdef CLIPPING
      if (!clipKeeps(p)) {
        k = kNext;
        continue;
      }
#endif
#if defined(MODE_MIP) && defined(CHANNELS)
      maxValue = channelsTakeMax(p);  // per channel maxima (render/channels.glsl)
#elif defined(MODE_MIP)
      maxValue = max(maxValue, normalizedValue(fieldValue(p)));
#elif defined(MODE_MINIP)
      minValue = min(minValue, normalizedValue(fieldValue(p)));
      kept += 1.0;
#elif defined(MODE_AVERAGE)
      sumValue += normalizedValue(fieldValue(p));
      kept += 1.0;
#else
#if defined(LOG_TRANSMITTANCE)
      // A sample stands for the stretch to the next one; the table's .a is
      // log2 of one base step's transmittance, so the stretch's is m times
      // it, and so is what it adds to the ray's.
      vec4 c = classifiedSample(p);
      float stretchLog2T = (kNext - k) * c.a;
      compositeFrontToBack(acc, vec4(c.rgb, 1.0 - exp2(stretchLog2T)));
      logT += stretchLog2T;
#elif defined(ADAPTIVE_SAMPLING)
      // A sample stands for the stretch to the next one.
      compositeFrontToBack(acc, stretchOpacity(classifiedSample(p), kNext - k));
#else
      compositeFrontToBack(acc, classifiedSample(p));
#endif
      if (acc.a >= u_ert) break;
#endif
#endif
      k = kNext;
    }
#ifdef LAYOUT_BRICK_WALK
    }
#endif
  }
#ifdef MODE_MIP
  if (maxValue >= 0.0) {
    // MIP shows the TF colour of the maximum, opaque (the classic MIP look:
    // with the grey preset the pixel is the maximum intensity).
    acc = vec4(classify(maxValue).rgb, 1.0);
#ifdef CHANNELS
    acc = channelsMaxColor();
#endif
  }
#elif defined(MODE_MINIP)
  if (kept > 0.0) acc = vec4(classify(minValue).rgb, 1.0);
#elif defined(MODE_AVERAGE)
  if (kept > 0.0) acc = vec4(classify(sumValue / kept).rgb, 1.0);
#endif
  FRAG_COLOR = overBackground(acc, u_background);
}
