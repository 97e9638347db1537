// Axis-aligned slices: a bilinear sample of the slice from its atlas tile,
// classified per CLASSIFY_PRE / CLASSIFY_PALETTE / post (render/Slice2DRenderer.h),
// with the opacity corrected for the distance the ray travels between drawn
// planes. In-tile coordinates are clamped to the centres of the tile's edge
// texels, so filtering never reaches the neighbouring tile (the atlas needs
// no gutters), which is clamp-to-edge for one slice.
#if TESSERA_GLSL == 300
in vec3 v_world;
in vec2 v_local;
in vec2 v_tileOrigin;
#else
varying vec3 v_world;
varying vec2 v_local;
varying vec2 v_tileOrigin;
#endif
uniform sampler2D u_atlas;
uniform vec2 u_tileSize;      // texels
uniform vec2 u_atlasInvSize;  // 1 / atlas size in texels
uniform vec3 u_axis;          // the stack's axis (unit vector)
uniform float u_gap;          // distance between drawn planes / the tables' distance
uniform vec3 u_eye;
uniform vec3 u_forward;
uniform float u_ortho;
#ifdef CLIPPING
uniform vec3 u_invExtent;  // world (model frame, box centred at 0) -> texture space
#endif
#ifdef CLASSIFY_PALETTE
uniform sampler2D u_palette;  // 256 premultiplied entries

vec4 paletteAt(vec2 texel) {
  float index = TEX2D(u_atlas, (v_tileOrigin + texel + 0.5) * u_atlasInvSize).r;
  return TEX2D(u_palette, vec2((index * 255.0 + 0.5) / 256.0, 0.5));
}
#endif
#ifdef SHADING
// Shaded stacks (SliceStacks::fillShadingAtlasBand): r the slice, g and b the
// slices below and above along the axis. Central differences one voxel
// apart, as the layout seam's gradient takes them: in the tile (clamped to
// its edge texels: clamp to edge) and across it from g and b.
uniform vec3 u_tileAxisU;  // model axis of the tile's x, y
uniform vec3 u_tileAxisV;
uniform vec3 u_halfDims;  // dims / 2 along tile x, tile y, the stack axis

float tileValue(vec2 texel) {
  vec2 t = clamp(texel, vec2(0.5), u_tileSize - vec2(0.5));
  return TEX2D(u_atlas, (v_tileOrigin + t) * u_atlasInvSize).r;
}

// The gradient of the normalised value per texture-space unit.
vec3 sliceGradient(vec2 texel, vec4 here) {
  float gu = (tileValue(texel + vec2(1.0, 0.0)) - tileValue(texel - vec2(1.0, 0.0))) * u_halfDims.x;
  float gv = (tileValue(texel + vec2(0.0, 1.0)) - tileValue(texel - vec2(0.0, 1.0))) * u_halfDims.y;
  float gw = (here.b - here.g) * u_halfDims.z;
  return u_tileAxisU * gu + u_tileAxisV * gv + u_axis * gw;
}
#endif

void main() {
  vec2 texel = clamp(v_local * u_tileSize, vec2(0.5), u_tileSize - vec2(0.5));
#ifdef NEAREST
  texel = floor(texel) + 0.5;  // the voxel's own value (the planes are voxel planes)
#endif
#if defined(CLASSIFY_PRE)
  vec4 c = TEX2D(u_atlas, (v_tileOrigin + texel) * u_atlasInvSize);
#elif defined(CLASSIFY_PALETTE)
  // Classify the four nearest indices, then filter (GL_PALETTE8 semantics).
  vec2 t = texel - 0.5;
  vec2 i0 = floor(t);
  vec2 f = t - i0;
  vec2 i1 = min(i0 + 1.0, u_tileSize - 1.0);
  vec4 c = mix(mix(paletteAt(i0), paletteAt(vec2(i1.x, i0.y)), f.x),
               mix(paletteAt(vec2(i0.x, i1.y)), paletteAt(i1), f.x), f.y);
#else
  vec4 here = TEX2D(u_atlas, (v_tileOrigin + texel) * u_atlasInvSize);
  float n = here.r;
#ifdef NEAREST
  // Labels are whole indices: undo the filter's sub-texel rounding, which
  // would mix in a neighbour's table entry.
  n = floor(n * 255.0 + 0.5) / 255.0;
#endif
#ifndef MODE_MIP
  vec4 c = classify(n);
#ifdef SHADING
  if (c.a > 0.0) c = shadeClassified(c, sliceGradient(texel, here) * u_shadeGradientScale);
#endif
  c.rgb *= c.a;
#endif
#endif
  float kept = 1.0;
#ifdef CLIPPING
  if (!clipKeeps(v_world * u_invExtent + 0.5)) kept = 0.0;
#endif
#ifdef MODE_MIP
  // Post-classification only: the resolve pass classifies the maximum.
  FRAG_COLOR = vec4(n, 0.0, 0.0, 1.0) * kept;
#else
  vec3 dir = u_ortho > 0.5 ? u_forward : normalize(v_world - u_eye);
  float ratio = u_gap / max(abs(dot(dir, u_axis)), 1e-3);
  FRAG_COLOR = correctOpacity(c, ratio) * kept;
#endif
}
