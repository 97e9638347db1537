// sampleVolume for MosaicLayout: z-slices tiled in one single-channel 2D
// texture (Noguera et al. 2012, GRAPP, section 3.1). Valid GLSL ES 1.00 and
// 3.00: float arithmetic only, TEX2D from the preamble.
//
// Trilinear = two hardware-bilinear fetches, in slices z0 and z1 around p.z,
// and a mix with the z weight. Clamp-to-edge in z: below the first slice
// centre or above the last, both fetches hit the edge slice.
//
// No bleeding between tiles without gutters: the in-tile coordinate is
// clamped to [0.5, W - 0.5] x [0.5, H - 0.5] texels, the centres of the
// tile's edge texels. Bilinear filtering there gives the edge texel full
// weight and its neighbour in the next tile none, which is exactly what
// CLAMP_TO_EDGE does for a texture of one slice, so the mosaic needs no
// border texels. (As for any texture, "none" holds up to the float
// rounding of the coordinate, a weight below size * 2^-23, which 8-bit
// filter weights such as llvmpipe's round to 0. Listing 2 of Noguera &
// Jimenez 2012 maps x straight to x / Mx inside the tile, so its fetches
// near a tile edge take up to half a weight from the neighbouring tile.)
#if TESSERA_GLSL == 300 || defined(GL_FRAGMENT_PRECISION_HIGH)
uniform highp sampler2D u_layoutMosaic;
#else
uniform mediump sampler2D u_layoutMosaic;
#endif
uniform vec3 u_layoutDims;     // W, H, D (voxels)
uniform float u_layoutTilesX;  // tiles per texture row
uniform vec2 u_layoutInvSize;  // 1 / texture size in texels

// Bilinear value of slice z (an integer in [0, D-1]) at in-tile texel
// coordinate `texel`.
float layoutMosaicSlice(float z, vec2 texel) {
  // Row and column of tile z without integer ops (GLSL ES 1.00 has no
  // integer division or modulo worth the name); the +0.5 keeps the quotient
  // half a tile away from an integer, so float rounding cannot flip floor().
  float row = floor((z + 0.5) / u_layoutTilesX);
  float col = z - row * u_layoutTilesX;
  return TEX2D(u_layoutMosaic, (vec2(col, row) * u_layoutDims.xy + texel) * u_layoutInvSize).r;
}

float sampleVolume(vec3 p) {
  vec2 texel = clamp(p.xy * u_layoutDims.xy, vec2(0.5), u_layoutDims.xy - vec2(0.5));
  float zc = p.z * u_layoutDims.z - 0.5;  // in slice-centre units
  float z0 = clamp(floor(zc), 0.0, u_layoutDims.z - 1.0);
  float z1 = min(z0 + 1.0, u_layoutDims.z - 1.0);
  return mix(layoutMosaicSlice(z0, texel), layoutMosaicSlice(z1, texel),
             clamp(zc - z0, 0.0, 1.0));
}
