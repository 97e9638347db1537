// sampleVolume for BricksLayout: bricks of several resolution levels in one
// atlas, found through a page table (Schultz 2016 §7.3; the page-table
// scheme of ImageVis3D and Neuroglancer). Valid GLSL ES 1.00 and 3.00.
//
// The page table has one RGBA8 texel per level-0 brick cell c (texel
// (c.x, c.y + c.z * cells.y), NEAREST): rgb = the atlas slot and a = the
// level l of the finest resident brick that covers the cell (the CPU falls
// back to coarser levels when finer bricks are missing, so there are no
// holes), or a = 255 when the cell is known to be transparent, with r the
// constant stored value to return. The brick of level l covering cell c is
// floor(c / 2^l); a level-l voxel spans 2^l level-0 voxels, so the level-0
// coordinate x0 is x0 / 2^l there. The slot stores (B + 2)^3 voxels, the
// brick and a one-voxel apron, so the hardware filter inside the slot is the
// trilinear interpolation of the level: no seams between bricks.
//
// On ES 3 the atlas is a 3D texture of slots; on ES 2 the same 3D atlas
// (slots stacked along z) is a mosaic of z-slices (MosaicLayout's
// addressing, layout/mosaic.glsl): two bilinear fetches and a mix.
#if TESSERA_GLSL == 300
uniform highp sampler2D u_layoutPages;
uniform highp sampler3D u_layoutAtlas;
#else
#ifdef GL_FRAGMENT_PRECISION_HIGH
uniform highp sampler2D u_layoutPages;
uniform highp sampler2D u_layoutAtlas;
#else
uniform mediump sampler2D u_layoutPages;
uniform mediump sampler2D u_layoutAtlas;
#endif
uniform float u_layoutTilesX;      // atlas mosaic: tiles per texture row
uniform vec2 u_layoutMosaicInv;    // 1 / mosaic texture size
#endif
uniform vec3 u_layoutDims0;        // level-0 voxels
uniform float u_layoutBrick;       // B
uniform vec3 u_layoutCells;        // level-0 brick cells
uniform vec2 u_layoutPagesInv;     // 1 / page table size
uniform vec3 u_layoutAtlasTexels;  // atlas (3D) size in texels

#if TESSERA_GLSL != 300
float layoutAtlasSlice(float z, vec2 texel) {
  float row = floor((z + 0.5) / u_layoutTilesX);
  float col = z - row * u_layoutTilesX;
  return TEX2D(u_layoutAtlas,
               (vec2(col, row) * u_layoutAtlasTexels.xy + texel) * u_layoutMosaicInv).r;
}
#endif

float sampleVolume(vec3 p) {
  vec3 x0 = clamp(p, 0.0, 1.0) * u_layoutDims0;
  vec3 cell = min(floor(x0 / u_layoutBrick), u_layoutCells - 1.0);
  vec4 page = TEX2D(u_layoutPages,
                    (vec2(cell.x, cell.y + cell.z * u_layoutCells.y) + 0.5) * u_layoutPagesInv);
  vec4 e = floor(page * 255.0 + 0.5);
  if (e.a > 254.5) return page.r;
  float shrink = exp2(-e.a);
  vec3 brick = floor(cell * shrink + 0.001);  // c >> l (the +0.001 guards exp2 rounding)
  vec3 local = clamp(x0 * shrink - brick * u_layoutBrick, 0.0, u_layoutBrick) + 1.0;
  vec3 texel = e.rgb * (u_layoutBrick + 2.0) + local;
#if TESSERA_GLSL == 300
  return texture(u_layoutAtlas, texel / u_layoutAtlasTexels).r;
#else
  float zc = texel.z - 0.5;
  float z0 = floor(zc);
  return mix(layoutAtlasSlice(z0, texel.xy), layoutAtlasSlice(z0 + 1.0, texel.xy), zc - z0);
#endif
}
