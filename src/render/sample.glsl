// One sample as every layout-based technique takes it: the layout's
// reconstruction (sampleVolume; with NEAREST the voxel's own value), the value window, the transfer
// function, and with SHADING the light (render/shading.glsl, from sampleVolumeGradient). Techniques
// call this instead of writing the chain in their main(), so a stage added here reaches all of
// them.
// With LAYOUT_BRICK_WALK (the ray caster's brick walk, raycast.frag.glsl) a
// sample's value comes from the brick cell the ray is in (the layout's
// sampleVolumeInCell, its page read once per cell); the gradient's
// neighbours may lie outside it and read through sampleVolume.
#ifdef LAYOUT_BRICK_WALK
#define FIELD_SAMPLE sampleVolumeInCell
#else
#define FIELD_SAMPLE sampleVolume
#endif

#ifdef NEAREST
uniform vec3 u_sampleDims;  // the volume's dims

// The value of the voxel whose cell holds p, read at its centre (where the
// layout's interpolation weights vanish): no interpolation across labels.
float fieldValue(vec3 p) {
  vec3 cell = clamp(floor(p * u_sampleDims), vec3(0.0), u_sampleDims - 1.0);
  return FIELD_SAMPLE((cell + 0.5) / u_sampleDims);
}
#else
float fieldValue(vec3 p) {
  return FIELD_SAMPLE(p);
}
#endif

// A lit sample's value and gradient from one fetch where the layout's seam
// offers both (the precomputed gradient holding 8-bit voxels,
// layout/gradient_texture.glsl): the same field, half the fetches.
#if defined(SHADING) && defined(LAYOUT_HAS_VALUE_AND_GRADIENT) && !defined(NEAREST)
#ifndef FUSION  // fusion.glsl mixes the fused volume in before the light
#define FUSED_VALUE_GRADIENT 1
#endif
#endif

#ifdef SHADING
// Straight colour c classified at p, lit; transparent samples skip the
// gradient's fetches. (Never with LOG_TRANSMITTANCE: only unlit frames read
// opacity as log2 of the transmittance.)
vec4 shadeSample(vec4 c, vec3 p) {
  if (c.a <= 0.0) return c;
  return shadeClassified(c, sampleVolumeGradient(p) * u_shadeGradientScale);
}
#endif

vec4 classifiedSample(vec3 p) {
#if defined(CHANNELS)
  return classifiedChannels(p);  // several channels (render/channels.glsl)
#elif defined(FUSED_VALUE_GRADIENT)
  vec4 vg = sampleVolumeAndGradient(p);
  return shadeClassified(classify(normalizedValue(vg.w)), vg.xyz * u_shadeGradientScale);
#else
  vec4 c = classify(normalizedValue(fieldValue(p)));
#ifdef FUSION
  c = fuseSample(c, p);  // a second volume over this one (render/fusion.glsl)
#endif
#ifdef SHADING
  c = shadeSample(c, p);
#endif
  return c;
#endif
}

#ifdef PREINTEGRATED
// The stored value at a segment's end p. Where lit samples read values from
// the gradient texture (FUSED_VALUE_GRADIENT), so does a lit segment, whose
// gradient comes from the same texture at its middle: one texture for both
// fetches is 1.04x faster on llvmpipe than the layout's next to it, the same
// image (docs/shading.md).
float segmentValue(vec3 p) {
#ifdef FUSED_VALUE_GRADIENT
  return sampleVolumeAndGradient(p).w;
#else
  return fieldValue(p);
#endif
}

// The pre-integrated segment from normalised value nf to nb standing for m
// base steps (m > 1 only with ADAPTIVE_SAMPLING), with SHADING lit by the
// gradient at pMid, the segment's middle: the gradient is fetched at
// another position than the ends' values (segmentValue()), because lighting
// an adaptive segment of up to 16 base steps by its ends' gradients cost up
// to 7 dB (docs/shading.md).
vec4 classifiedSegment(float nf, float nb, float m, vec3 pMid) {
#ifdef LOG_TRANSMITTANCE
  vec4 c = classifySegment(nf, nb);  // .a: log2 of one base step's transmittance
#elif defined(ADAPTIVE_SAMPLING)
  vec4 c = stretchOpacity(classifySegment(nf, nb), m);
#else
  vec4 c = classifySegment(nf, nb);  // m = 1: consecutive samples
#endif
#ifdef SHADING
  c = shadeSample(c, pMid);
#endif
  return c;
}
#endif
