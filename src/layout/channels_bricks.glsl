// Line 1 is replaced by "#define CHANNEL_GROUPS <G>" (BricksLayout::channelsGlsl).
// Several channels in the bricks layout (BricksLayout::createChannels): after
// layout/bricks.glsl, whose page lookup (brickPage) and brick walk
// (layoutEnterCell) it reuses. A slot holds every channel of its brick, four
// per RGBA texel: group 0 (channels 0-3) and group 1 (4-5) at the same slot.
// ES 3: one 3D atlas a group, u_layoutChannels0 (bricks.glsl's u_layoutAtlas)
// and u_layoutChannels1, filtered in hardware. ES 2: a group's slots spread
// over BRICKS_ATLASES mosaics (page r = mosaic, b = slot in its stack, 255
// each: layout/ChannelBricks.cpp), group 0's being bricks.glsl's
// u_layoutAtlas0..7 and group 1's u_layoutChannels1_0..7; two bilinear
// fetches of the slot's mosaic and a mix (as bricks.glsl).
//
// With LAYOUT_BRICK_WALK (the ray caster's brick walk) the page is read once
// when the ray enters a brick cell (bricks.glsl's walkPage) and every channel
// of every sample in the cell reads that slot: the brick geometry is shared
// by the channels. Channel pages are never constant (one constant cannot
// stand for several channels: BricksLayout::transparent), so the walk never
// skips a cell as transparent.
#define CHANNELS 1
#define LAYOUT_HAS_SAMPLE_VOLUME 1  // bricks.glsl's: channel 0, the atlas' .r
#if TESSERA_GLSL == 300
uniform highp sampler3D u_layoutChannels0;
uniform highp sampler3D u_layoutChannels1;
#elif CHANNEL_GROUPS > 1
BRICKS_SAMPLER u_layoutChannels1_0;
#if BRICKS_ATLASES > 1
BRICKS_SAMPLER u_layoutChannels1_1;
#endif
#if BRICKS_ATLASES > 2
BRICKS_SAMPLER u_layoutChannels1_2;
#endif
#if BRICKS_ATLASES > 3
BRICKS_SAMPLER u_layoutChannels1_3;
#endif
#if BRICKS_ATLASES > 4
BRICKS_SAMPLER u_layoutChannels1_4;
#endif
#if BRICKS_ATLASES > 5
BRICKS_SAMPLER u_layoutChannels1_5;
#endif
#if BRICKS_ATLASES > 6
BRICKS_SAMPLER u_layoutChannels1_6;
#endif
#if BRICKS_ATLASES > 7
BRICKS_SAMPLER u_layoutChannels1_7;
#endif
#endif

#if TESSERA_GLSL != 300
// Slice z's texture coordinate of in-slice texel `texel` (bricks.glsl's
// layoutAtlasSlice addressing).
vec2 layoutChannelSliceUv(float z, vec2 texel) {
  float row = floor((z + 0.5) / u_layoutTilesX);
  float col = z - row * u_layoutTilesX;
  return (vec2(col, row) * u_layoutAtlasTexels.xy + texel) * u_layoutMosaicInv;
}

// Group 0's mosaic t at uv (samplers take constant indices only in GLSL ES
// 1.00: a chain, as bricks.glsl's layoutAtlasSlice).
vec4 layoutChannelMosaic0(float t, vec2 uv) {
#if BRICKS_ATLASES > 7
  if (t > 6.5) return TEX2D(u_layoutAtlas7, uv);
#endif
#if BRICKS_ATLASES > 6
  if (t > 5.5) return TEX2D(u_layoutAtlas6, uv);
#endif
#if BRICKS_ATLASES > 5
  if (t > 4.5) return TEX2D(u_layoutAtlas5, uv);
#endif
#if BRICKS_ATLASES > 4
  if (t > 3.5) return TEX2D(u_layoutAtlas4, uv);
#endif
#if BRICKS_ATLASES > 3
  if (t > 2.5) return TEX2D(u_layoutAtlas3, uv);
#endif
#if BRICKS_ATLASES > 2
  if (t > 1.5) return TEX2D(u_layoutAtlas2, uv);
#endif
#if BRICKS_ATLASES > 1
  if (t > 0.5) return TEX2D(u_layoutAtlas1, uv);
#endif
  return TEX2D(u_layoutAtlas0, uv);
}

vec4 layoutChannelMosaic1(float t, vec2 uv) {
#if CHANNEL_GROUPS > 1
#if BRICKS_ATLASES > 7
  if (t > 6.5) return TEX2D(u_layoutChannels1_7, uv);
#endif
#if BRICKS_ATLASES > 6
  if (t > 5.5) return TEX2D(u_layoutChannels1_6, uv);
#endif
#if BRICKS_ATLASES > 5
  if (t > 4.5) return TEX2D(u_layoutChannels1_5, uv);
#endif
#if BRICKS_ATLASES > 4
  if (t > 3.5) return TEX2D(u_layoutChannels1_4, uv);
#endif
#if BRICKS_ATLASES > 3
  if (t > 2.5) return TEX2D(u_layoutChannels1_3, uv);
#endif
#if BRICKS_ATLASES > 2
  if (t > 1.5) return TEX2D(u_layoutChannels1_2, uv);
#endif
#if BRICKS_ATLASES > 1
  if (t > 0.5) return TEX2D(u_layoutChannels1_1, uv);
#endif
  return TEX2D(u_layoutChannels1_0, uv);
#else
  return vec4(0.0);  // no channels 4-5 (u_layoutChannelTextures = 1)
#endif
}

// The texels of group `group` at slot texel coordinates `t` of brick b.
vec4 layoutChannelBrickTexel(float group, BrickPage b, vec3 t) {
  float zc = t.z - 0.5;
  float z0 = floor(zc);
  vec2 uv0 = layoutChannelSliceUv(z0, t.xy);
  vec2 uv1 = layoutChannelSliceUv(z0 + 1.0, t.xy);
  return group < 0.5 ? mix(layoutChannelMosaic0(b.atlas, uv0), layoutChannelMosaic0(b.atlas, uv1),
                             zc - z0)
                       : mix(layoutChannelMosaic1(b.atlas, uv0), layoutChannelMosaic1(b.atlas, uv1),
                             zc - z0);
}
#endif

#ifdef LAYOUT_BRICK_WALK
// In the cell entered last (bricks.glsl's layoutEnterCell): the sample lies
// in the cell's brick up to rounding, which the apron covers.
#if TESSERA_GLSL == 300
vec4 layoutChannelTexel0(vec3 p) {
  return texture(u_layoutChannels0, p * walkScale + walkOffset);
}
vec4 layoutChannelTexel1(vec3 p) {
  return texture(u_layoutChannels1, p * walkScale + walkOffset);
}
#else
vec4 layoutChannelTexel0(vec3 p) {
  return layoutChannelBrickTexel(0.0, walkPage, p * walkPage.scale + walkPage.offset);
}
vec4 layoutChannelTexel1(vec3 p) {
  return layoutChannelBrickTexel(1.0, walkPage, p * walkPage.scale + walkPage.offset);
}
#endif
#else
// Per sample (slice3d, or BricksOptions::walk false): the page of the cell
// holding p, read for each group.
BrickPage layoutChannelPage(vec3 p, out vec3 texel) {
  vec3 q = clamp(p, 0.0, 1.0);
  BrickPage b = brickPage(q * u_layoutDims0);
  texel = clamp(q * b.scale + b.offset, b.lo, b.hi);
  return b;
}

#if TESSERA_GLSL == 300
vec4 layoutChannelTexel0(vec3 p) {
  vec3 t;
  layoutChannelPage(p, t);
  return texture(u_layoutChannels0, t / u_layoutAtlasTexels);
}
vec4 layoutChannelTexel1(vec3 p) {
  vec3 t;
  layoutChannelPage(p, t);
  return texture(u_layoutChannels1, t / u_layoutAtlasTexels);
}
#else
vec4 layoutChannelTexel0(vec3 p) {
  vec3 t;
  BrickPage b = layoutChannelPage(p, t);
  return layoutChannelBrickTexel(0.0, b, t);
}
vec4 layoutChannelTexel1(vec3 p) {
  vec3 t;
  BrickPage b = layoutChannelPage(p, t);
  return layoutChannelBrickTexel(1.0, b, t);
}
#endif
#endif
