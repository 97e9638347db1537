// Post-classification through the baked transfer function: u_tf holds
// u_tfSize entries, entry i at normalised value i/(u_tfSize-1), opacity
// already corrected for the sample distance (TransferFunction::bake).
uniform sampler2D u_tf;
uniform float u_tfSize;
uniform float u_valueScale;  // normalised = clamp(stored * scale + bias, 0, 1)
uniform float u_valueBias;

float normalizedValue(float stored) { return clamp(stored * u_valueScale + u_valueBias, 0.0, 1.0); }

vec4 classify(float n) {
#ifdef TF_NEAREST_ENTRY
  // A fine table (4096 entries): the nearest entry, one unfiltered fetch,
  // within 1/8190 of the value the linear lookup below reads at (far below an
  // 8-bit voxel's step); a software rasteriser pays for every fetch (the web
  // page's frame at step 1: 1.10x faster under SwiftShader, bench/web-peers).
  float i = floor(n * (u_tfSize - 1.0) + 0.5);
#if TESSERA_GLSL == 300
  return texelFetch(u_tf, ivec2(int(i), 0), 0);
#else
  return texture2D(u_tf, vec2((i + 0.5) / u_tfSize, 0.5));
#endif
#elif TESSERA_GLSL == 300
  // Linear between entries floor(x) and floor(x) + 1 from two texel fetches:
  // the table's LINEAR filter computed in the shader, which software
  // rasterisers (SwiftShader in browsers) run far faster than a filtered
  // fetch of the half-float table (bench/web-peers).
  float x = n * (u_tfSize - 1.0);
  float x0 = min(floor(x), u_tfSize - 2.0);
  vec4 a = texelFetch(u_tf, ivec2(int(x0), 0), 0);
  vec4 b = texelFetch(u_tf, ivec2(int(x0) + 1, 0), 0);
  return mix(a, b, x - x0);
#else
  // The same from two unfiltered fetches at texel centres (the ray caster
  // samples its table with NEAREST filtering).
  float x = n * (u_tfSize - 1.0);
  float x0 = min(floor(x), u_tfSize - 2.0);
  vec4 a = texture2D(u_tf, vec2((x0 + 0.5) / u_tfSize, 0.5));
  vec4 b = texture2D(u_tf, vec2((x0 + 1.5) / u_tfSize, 0.5));
  return mix(a, b, x - x0);
#endif
}

// A sample or segment that stands for m base steps (adaptive sampling): its
// opacity for the longer stretch, a' = 1 - (1 - a)^m (AdaptiveSteps.h).
vec4 stretchOpacity(vec4 c, float m) {
  return m == 1.0 ? c : vec4(c.rgb, 1.0 - pow(max(1.0 - c.a, 0.0), m));
}

#ifdef PREINTEGRATED
// Pre-integrated classification (reference/PreIntegration.h): straight colour
// and the opacity of one base step for the segment on which the normalised
// value runs from nf (front) to nb (back); u_preint holds u_preintSize^2
// entries, front along x (render/PreIntegrationTable.h).
uniform sampler2D u_preint;
uniform float u_preintSize;

vec4 classifySegment(float nf, float nb) {
  return TEX2D(u_preint, (vec2(nf, nb) * (u_preintSize - 1.0) + 0.5) / u_preintSize);
}
#endif
