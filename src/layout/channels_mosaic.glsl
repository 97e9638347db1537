// Several channels for ChannelLayout without 3D textures (ES 2): the
// z-slices tiled in RGBA8 mosaics as layout/mosaic.glsl tiles one channel,
// four channels per texel; trilinear = two bilinear fetches per mosaic, the
// in-tile coordinate clamped to the edge texels' centres (no bleeding, no
// gutters; see mosaic.glsl). layout/channels.glsl follows.
#define CHANNELS 1
#if TESSERA_GLSL == 300 || defined(GL_FRAGMENT_PRECISION_HIGH)
uniform highp sampler2D u_layoutChannels0;
uniform highp sampler2D u_layoutChannels1;
#else
uniform mediump sampler2D u_layoutChannels0;
uniform mediump sampler2D u_layoutChannels1;
#endif
uniform vec3 u_layoutDims;     // W, H, D (voxels)
uniform float u_layoutTilesX;  // tiles per texture row
uniform vec2 u_layoutInvSize;  // 1 / texture size in texels

// Where slice z's tile starts (texels) and the in-tile coordinate of p,
// as mosaic.glsl computes them.
vec2 layoutChannelTile(float z) {
  float row = floor((z + 0.5) / u_layoutTilesX);
  return vec2(z - row * u_layoutTilesX, row) * u_layoutDims.xy;
}

// The texture coordinates of p's two slices, z0 (a) and z1 (b), and the
// weight of b.
float layoutChannelCoords(vec3 p, out vec2 a, out vec2 b) {
  vec2 texel = clamp(p.xy * u_layoutDims.xy, vec2(0.5), u_layoutDims.xy - vec2(0.5));
  float zc = p.z * u_layoutDims.z - 0.5;
  float z0 = clamp(floor(zc), 0.0, u_layoutDims.z - 1.0);
  float z1 = min(z0 + 1.0, u_layoutDims.z - 1.0);
  a = (layoutChannelTile(z0) + texel) * u_layoutInvSize;
  b = (layoutChannelTile(z1) + texel) * u_layoutInvSize;
  return clamp(zc - z0, 0.0, 1.0);
}

vec4 layoutChannelTexel0(vec3 p) {
  vec2 a;
  vec2 b;
  float w = layoutChannelCoords(p, a, b);
  return mix(TEX2D(u_layoutChannels0, a), TEX2D(u_layoutChannels0, b), w);
}

vec4 layoutChannelTexel1(vec3 p) {
  vec2 a;
  vec2 b;
  float w = layoutChannelCoords(p, a, b);
  return mix(TEX2D(u_layoutChannels1, a), TEX2D(u_layoutChannels1, b), w);
}
