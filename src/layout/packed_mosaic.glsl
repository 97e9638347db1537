// Line 1 is replaced by "#define TESSERA_PACKED_TEXTURES <N>" (PackedMosaicLayout::glsl()),
// line 2 by "#define TESSERA_PACKED_OVERLAPPED <0|1>".
// sampleVolume for PackedMosaicLayout, tiles in row-major grids of T per
// texture over N RGBA8 textures. Dense: slice s in channel s % 4 of tile
// s / 4, two fetches per sample. Overlapped: channel c of tile g holds slice
// min(3g + c, D - 1), so slices z0 and z0 + 1 share a texel: one fetch per
// sample (the packings, and why they beat Noguera & Jimenez 2012's Listings
// 1-2, are in PackedMosaicLayout.h). Valid GLSL ES 1.00 and 3.00: float
// arithmetic only (ES 1.00 has no integer bit ops), TEX2D from the preamble.
//
// No bleeding between tiles, as in mosaic.glsl: the in-tile coordinate is
// clamped to the centres of the tile's edge texels, [0.5, W - 0.5] x
// [0.5, H - 0.5], where bilinear filtering gives the neighbouring tile zero
// weight — exactly CLAMP_TO_EDGE, with no gutters.
#if !defined(TESSERA_PACKED_TEXTURES) || !defined(TESSERA_PACKED_OVERLAPPED)
#error "TESSERA_PACKED_TEXTURES and _OVERLAPPED must be defined (PackedMosaicLayout::glsl())"
#endif

#if TESSERA_GLSL == 300 || defined(GL_FRAGMENT_PRECISION_HIGH)
uniform highp sampler2D u_layoutTextures[TESSERA_PACKED_TEXTURES];
#else
uniform mediump sampler2D u_layoutTextures[TESSERA_PACKED_TEXTURES];
#endif
uniform vec3 u_layoutDims;     // W, H, D (voxels)
uniform vec2 u_layoutTiles;    // tiles per texture row and column (X, Y; T = X * Y)
uniform vec2 u_layoutInvTiles; // 1 / u_layoutTiles: multiplies, cheaper than divides
uniform vec2 u_layoutInvSize;  // 1 / texture size in texels (all textures alike)

// The texel at `uv` of texture t. GLSL ES 1.00 (Appendix A) lets a sampler
// array be indexed by constant index expressions only, and ES 3.00 by
// constant expressions only, so texture t is chosen by a chain of ifs with
// constant indices. It is the one branch of the layout, and a coherent one:
// a ray crosses into another texture once per 4T (overlapped 3T) slices, so
// the pixels of a quad almost always take the same branch. Fetching all N
// textures and masking would be branch-free but cost N fetches per slice.
vec4 layoutPackedFetch(float t, vec2 uv) {
#if TESSERA_PACKED_TEXTURES > 1
  if (t < 0.5) return TEX2D(u_layoutTextures[0], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 2
  if (t < 1.5) return TEX2D(u_layoutTextures[1], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 3
  if (t < 2.5) return TEX2D(u_layoutTextures[2], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 4
  if (t < 3.5) return TEX2D(u_layoutTextures[3], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 5
  if (t < 4.5) return TEX2D(u_layoutTextures[4], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 6
  if (t < 5.5) return TEX2D(u_layoutTextures[5], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 7
  if (t < 6.5) return TEX2D(u_layoutTextures[6], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 8
  if (t < 7.5) return TEX2D(u_layoutTextures[7], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 9
  if (t < 8.5) return TEX2D(u_layoutTextures[8], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 10
  if (t < 9.5) return TEX2D(u_layoutTextures[9], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 11
  if (t < 10.5) return TEX2D(u_layoutTextures[10], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 12
  if (t < 11.5) return TEX2D(u_layoutTextures[11], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 13
  if (t < 12.5) return TEX2D(u_layoutTextures[12], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 14
  if (t < 13.5) return TEX2D(u_layoutTextures[13], uv);
#endif
#if TESSERA_PACKED_TEXTURES > 15
  if (t < 14.5) return TEX2D(u_layoutTextures[14], uv);
#endif
  return TEX2D(u_layoutTextures[TESSERA_PACKED_TEXTURES - 1], uv);
}

// The bilinear RGBA texel of tile `tile` (an integer) at in-tile texel
// coordinate `texel`. A texture holds Y whole rows of X tiles, so the tile's
// row counted over all textures gives column, texture and row in the
// texture. Every quotient below is of an integer n plus one half by an
// integer X, at least 0.5 / X from an integer, so float rounding cannot
// flip floor() (what mod() on floats would risk); multiplying by 1 / X
// instead of dividing adds an error of ~1e-7 of the quotient, n / X * 1e-7,
// below that margin for any n under a million.
vec4 layoutPackedTexel(float tile, vec2 texel) {
  float rows = floor((tile + 0.5) * u_layoutInvTiles.x);
  float col = tile - rows * u_layoutTiles.x;
#if TESSERA_PACKED_TEXTURES > 1
  float t = floor((rows + 0.5) * u_layoutInvTiles.y);
  float row = rows - t * u_layoutTiles.y;
#else
  float t = 0.0;  // one texture: no texture index to find
  float row = rows;
#endif
  return layoutPackedFetch(t, (vec2(col, row) * u_layoutDims.xy + texel) * u_layoutInvSize);
}

#if TESSERA_PACKED_OVERLAPPED
// Trilinear in one fetch. z0 is kept to [0, D-2] (0 for D = 1) so that
// z0 + 1 always exists, and the z weight does the clamp-to-edge: below the
// first slice centre it is 0 (slice 0), above the last 1 (slice D-1). Tile
// g = floor(z0 / 3) holds z0 in channel z0 - 3g (0, 1 or 2) and z0 + 1 in
// the next; at zl = z0 - 3g + f the hat weights max(1 - |i - zl|, 0) of
// channels i = 0..3 are 1 - f and f on those two and 0 on the others — the
// z lerp and the channel select in one branch-free dot(), no mask compare.
// f = 0 or 1 (voxel centres) gives exactly one-hot weights.
float sampleVolume(vec3 p) {
  vec2 texel = clamp(p.xy * u_layoutDims.xy, vec2(0.5), u_layoutDims.xy - vec2(0.5));
  float zc = p.z * u_layoutDims.z - 0.5;  // in slice-centre units
  float z0 = clamp(floor(zc), 0.0, max(u_layoutDims.z - 2.0, 0.0));
  float tile = floor((z0 + 0.5) * (1.0 / 3.0));
  float zl = z0 - 3.0 * tile + clamp(zc - z0, 0.0, 1.0);
  return dot(layoutPackedTexel(tile, texel), max(1.0 - abs(vec4(0.0, 1.0, 2.0, 3.0) - zl), 0.0));
}
#else
// Bilinear value of slice z (an integer in [0, D-1]) at in-tile texel
// coordinate `texel`.
float layoutPackedSlice(float z, vec2 texel) {
  float tile = floor((z + 0.5) * 0.25);
  float channel = z - 4.0 * tile;
  vec4 rgba = layoutPackedTexel(tile, texel);
  // Branch-free channel select: a one-hot mask instead of rgba[int(channel)].
  return dot(rgba, vec4(equal(vec4(channel), vec4(0.0, 1.0, 2.0, 3.0))));
}

// Trilinear = bilinear in slices z0 and z1 around p.z and a mix; clamp-to-
// edge in z: below the first slice centre or above the last, both fetches
// hit the edge slice. z0 and z1 are addressed independently, so a pair that
// straddles a channel, tile or texture seam needs nothing special; 3 times
// out of 4 they share a texel and the second fetch hits the texture cache.
float sampleVolume(vec3 p) {
  vec2 texel = clamp(p.xy * u_layoutDims.xy, vec2(0.5), u_layoutDims.xy - vec2(0.5));
  float zc = p.z * u_layoutDims.z - 0.5;  // in slice-centre units
  float z0 = clamp(floor(zc), 0.0, u_layoutDims.z - 1.0);
  float z1 = min(z0 + 1.0, u_layoutDims.z - 1.0);
  return mix(layoutPackedSlice(z0, texel), layoutPackedSlice(z1, texel),
             clamp(zc - z0, 0.0, 1.0));
}
#endif
