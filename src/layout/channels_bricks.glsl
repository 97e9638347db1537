// Several channels in the bricks layout (BricksLayout::createChannels): after
// layout/bricks.glsl, whose page lookup (brickPage) it reuses. A slot holds
// every channel of its brick, four per RGBA texel: channels 0-3 in
// u_layoutChannels0 (the atlas bricks.glsl reads as u_layoutAtlas), 4-5 in
// u_layoutChannels1, the same slot. One page read serves the four channels
// of a texture; ES 3 filters in hardware, ES 2 mixes two bilinear fetches
// of the slot's mosaic (as bricks.glsl). layout/channels.glsl follows.
#define CHANNELS 1
#define LAYOUT_HAS_SAMPLE_VOLUME 1  // bricks.glsl's: channel 0, the atlas' .r
#if TESSERA_GLSL == 300
uniform highp sampler3D u_layoutChannels0;
uniform highp sampler3D u_layoutChannels1;
#else
BRICKS_SAMPLER u_layoutChannels0;
BRICKS_SAMPLER u_layoutChannels1;
#endif

// p's texel coordinate in the slot of the brick its page names.
vec3 layoutChannelSlotTexel(vec3 p) {
  vec3 q = clamp(p, 0.0, 1.0);
  BrickPage b = brickPage(q * u_layoutDims0);
  return clamp(q * b.scale + b.offset, b.lo, b.hi);
}

#if TESSERA_GLSL == 300
vec4 layoutChannelTexel0(vec3 p) {
  return texture(u_layoutChannels0, layoutChannelSlotTexel(p) / u_layoutAtlasTexels);
}
vec4 layoutChannelTexel1(vec3 p) {
  return texture(u_layoutChannels1, layoutChannelSlotTexel(p) / u_layoutAtlasTexels);
}
#else
// Slice z's texture coordinate of in-slice texel `texel` (bricks.glsl's
// layoutAtlasSlice addressing).
vec2 layoutChannelSliceUv(float z, vec2 texel) {
  float row = floor((z + 0.5) / u_layoutTilesX);
  float col = z - row * u_layoutTilesX;
  return (vec2(col, row) * u_layoutAtlasTexels.xy + texel) * u_layoutMosaicInv;
}

vec4 layoutChannelTexel0(vec3 p) {
  vec3 t = layoutChannelSlotTexel(p);
  float zc = t.z - 0.5;
  float z0 = floor(zc);
  return mix(TEX2D(u_layoutChannels0, layoutChannelSliceUv(z0, t.xy)),
             TEX2D(u_layoutChannels0, layoutChannelSliceUv(z0 + 1.0, t.xy)), zc - z0);
}
vec4 layoutChannelTexel1(vec3 p) {
  vec3 t = layoutChannelSlotTexel(p);
  float zc = t.z - 0.5;
  float z0 = floor(zc);
  return mix(TEX2D(u_layoutChannels1, layoutChannelSliceUv(z0, t.xy)),
             TEX2D(u_layoutChannels1, layoutChannelSliceUv(z0 + 1.0, t.xy)), zc - z0);
}
#endif
