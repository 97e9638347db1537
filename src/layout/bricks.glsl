// Line 1 is replaced by "#define BRICKS_ATLASES <N>" (BricksLayout::glsl()),
// line 2 by "#define BRICKS_TEXEL <T>": how a stored value is read (below),
// line 3 by "#define BRICKS_LEVELS <L>": the pyramid's levels,
// line 4 by "#define BRICKS_WALK_PAGES <0|1>": the walk reads float pages.
// sampleVolume for BricksLayout: bricks of several resolution levels in one
// atlas, found through a page table (Schultz 2016 §7.3; the page-table
// scheme of ImageVis3D and Neuroglancer). Valid GLSL ES 1.00 and 3.00.
//
// The page table has one RGBA8 texel per level-0 brick cell c, NEAREST, its
// z-slices side by side as tiles of cells.x x cells.y texels, u_layoutPageTiles
// per row (MosaicLayout::Geometry's addressing: texel (c.x + (c.z % tiles) *
// cells.x, c.y + floor(c.z / tiles) * cells.y), so the table fits the 2D
// limit however deep the grid; pageTexel below): rgb = the atlas slot and a = the
// level l of the finest resident brick that covers the cell (the CPU falls
// back to coarser levels when finer bricks are missing, so there are no
// holes), or a = 255 when the cell is known to be transparent, with r the
// constant stored value to return. A level-l voxel spans s_l level-0 voxels
// per axis (lod::BrickGrid::scale: 2^l on every axis in a factor-2 pyramid,
// (1, 2^l, 2^l) in one that keeps z), so the level-0 coordinate x0 is
// x0 / s_l there (layoutLevelShrink) and the brick of level l covering cell
// c is floor(c / s_l). The slot stores (B + 2)^3 voxels, the
// brick and a one-voxel apron, so the hardware filter inside the slot is the
// trilinear interpolation of the level: no seams between bricks.
//
// On ES 3 the atlas is a 3D texture of slots (page rgb = slot); on ES 2 the
// slots are stacked along z in up to 8 textures, each a mosaic of z-slices
// (MosaicLayout's addressing, layout/mosaic.glsl): page r = texture, b =
// slot in its stack; two bilinear fetches and a mix.
//
// Stored values keep the data's precision (lod::StoredMapping): BRICKS_TEXEL
// 0: 8 bits in .r (R8, LUMINANCE); 1: 16 bits in .r (R16, normalised); 2 and
// 3: 16 bits as a low and a high byte in .r and .g (RG8) or .r and .a
// (LUMINANCE_ALPHA), sampled NEAREST and interpolated after recombining (8
// fetches a sample instead of 1 or 2). A transparent cell's constant value is
// the page texel's r (8 bits) or r + 256 g (16 bits).
#if BRICKS_TEXEL == 2
#define BRICKS_VALUE(t) dot((t).rg, vec2(255.0 / 65535.0, 65280.0 / 65535.0))
#elif BRICKS_TEXEL == 3
#define BRICKS_VALUE(t) dot((t).ra, vec2(255.0 / 65535.0, 65280.0 / 65535.0))
#else
#define BRICKS_VALUE(t) (t).r
#endif
#if TESSERA_GLSL == 300
uniform highp sampler2D u_layoutPages;
uniform highp sampler3D u_layoutAtlas;
#else
#ifdef GL_FRAGMENT_PRECISION_HIGH
#define BRICKS_SAMPLER uniform highp sampler2D
#else
#define BRICKS_SAMPLER uniform mediump sampler2D
#endif
BRICKS_SAMPLER u_layoutPages;
BRICKS_SAMPLER u_layoutAtlas0;
#if BRICKS_ATLASES > 1
BRICKS_SAMPLER u_layoutAtlas1;
#endif
#if BRICKS_ATLASES > 2
BRICKS_SAMPLER u_layoutAtlas2;
#endif
#if BRICKS_ATLASES > 3
BRICKS_SAMPLER u_layoutAtlas3;
#endif
#if BRICKS_ATLASES > 4
BRICKS_SAMPLER u_layoutAtlas4;
#endif
#if BRICKS_ATLASES > 5
BRICKS_SAMPLER u_layoutAtlas5;
#endif
#if BRICKS_ATLASES > 6
BRICKS_SAMPLER u_layoutAtlas6;
#endif
#if BRICKS_ATLASES > 7
BRICKS_SAMPLER u_layoutAtlas7;
#endif
uniform float u_layoutTilesX;      // atlas mosaic: tiles per texture row
uniform vec2 u_layoutMosaicInv;    // 1 / mosaic texture size
#endif
uniform vec3 u_layoutDims0;        // level-0 voxels
uniform float u_layoutBrick;       // B
uniform vec3 u_layoutCells;        // level-0 brick cells
uniform vec2 u_layoutPagesInv;     // 1 / page table size
uniform float u_layoutPageTiles;   // page table: z-slice tiles per row
uniform vec3 u_layoutAtlasTexels;  // atlas (3D) size in texels
uniform vec3 u_layoutLevelShrink[BRICKS_LEVELS];  // 1 / s_l per level (see above)

// Level-l voxels per level-0 voxel along each axis: x_l = x0 * this.
vec3 layoutLevelShrink(float level) {
  // GLSL ES 1.00 (Appendix A) indexes uniforms by constant-index expressions
  // only, the loop's index being one (the conformance test holds ES 3.00
  // shaders to the same rule).
  vec3 s = u_layoutLevelShrink[0];
  for (int i = 1; i < BRICKS_LEVELS; i++) {
    if (float(i) == level) s = u_layoutLevelShrink[i];
  }
  return s;
}

#if TESSERA_GLSL != 300
// Slice z of atlas texture t (samplers take constant indices only in GLSL
// ES 1.00: an if-chain, as in packed_mosaic.glsl).
float layoutAtlasSlice(float t, float z, vec2 texel) {
  float row = floor((z + 0.5) / u_layoutTilesX);
  float col = z - row * u_layoutTilesX;
  vec2 uv = (vec2(col, row) * u_layoutAtlasTexels.xy + texel) * u_layoutMosaicInv;
#if BRICKS_ATLASES > 1
  if (t > 0.5) {
#if BRICKS_ATLASES > 2
    if (t > 1.5) {
#if BRICKS_ATLASES > 3
      if (t > 2.5) {
#if BRICKS_ATLASES > 4
        if (t > 3.5) {
#if BRICKS_ATLASES > 5
          if (t > 4.5) {
#if BRICKS_ATLASES > 6
            if (t > 5.5) {
#if BRICKS_ATLASES > 7
              if (t > 6.5) return BRICKS_VALUE(TEX2D(u_layoutAtlas7, uv));
#endif
              return BRICKS_VALUE(TEX2D(u_layoutAtlas6, uv));
            }
#endif
            return BRICKS_VALUE(TEX2D(u_layoutAtlas5, uv));
          }
#endif
          return BRICKS_VALUE(TEX2D(u_layoutAtlas4, uv));
        }
#endif
        return BRICKS_VALUE(TEX2D(u_layoutAtlas3, uv));
      }
#endif
      return BRICKS_VALUE(TEX2D(u_layoutAtlas2, uv));
    }
#endif
    return BRICKS_VALUE(TEX2D(u_layoutAtlas1, uv));
  }
#endif
  return BRICKS_VALUE(TEX2D(u_layoutAtlas0, uv));
}
#endif

// The page of one level-0 cell, decoded into the affine map from texture
// space p to the texel coordinates of its brick's slot: texel = clamp(p *
// scale + offset, lo, hi) (the brick and its apron: [lo - 1, hi + 1]); a
// transparent cell (page a = 255) returns `constant` instead (isConstant 1).
struct BrickPage {
  vec3 scale;
  vec3 offset;
  vec3 lo;
  vec3 hi;
  float atlas;  // ES 2: the atlas texture
  float constant;
  float isConstant;
};

// The page table texel of level-0 cell `cell` (whole numbers, exact in
// float: the table is at most the 2D limit on a side).
vec2 pageTexel(vec3 cell) {
  float row = floor((cell.z + 0.5) / u_layoutPageTiles);
  float col = cell.z - row * u_layoutPageTiles;
  return cell.xy + vec2(col, row) * u_layoutCells.xy;
}

// The page of the level-0 cell holding x0 (level-0 voxels, inside the volume).
BrickPage brickPage(vec3 x0) {
  vec3 cell = min(floor(x0 / u_layoutBrick), u_layoutCells - 1.0);
#if TESSERA_GLSL == 300
  vec4 page = texelFetch(u_layoutPages, ivec2(pageTexel(cell)), 0);
#else
  vec4 page = TEX2D(u_layoutPages, (pageTexel(cell) + 0.5) * u_layoutPagesInv);
#endif
  vec4 e = floor(page * 255.0 + 0.5);
  BrickPage b;
  b.isConstant = step(254.5, e.a);
#if BRICKS_TEXEL == 0
  b.constant = page.r;
#else
  b.constant = (e.r + 256.0 * e.g) / 65535.0;
#endif
  float level = e.a * (1.0 - b.isConstant);  // a constant cell reads slot 0 and is replaced
  vec3 shrink = layoutLevelShrink(level);  // 1 / s_l per axis
#if TESSERA_GLSL == 300
  vec3 slot = e.rgb * (1.0 - b.isConstant);
#else
  vec3 slot = vec3(0.0, 0.0, e.b * (1.0 - b.isConstant));
#endif
  b.atlas = e.r * (1.0 - b.isConstant);
  vec3 brick = floor(cell * shrink + 0.001);  // c / s_l (the +0.001 guards 1 / s_l's rounding)
  // Level-l coordinate x0 * shrink, local to the brick, + 1 for the apron.
  b.lo = slot * (u_layoutBrick + 2.0) + 1.0;
  b.hi = b.lo + u_layoutBrick;
  b.scale = u_layoutDims0 * shrink;
  b.offset = b.lo - brick * u_layoutBrick;
  return b;
}

// The value at texel coordinates `texel` of the slot of brick `b`.
float brickValue(BrickPage b, vec3 texel) {
  float v;
#if TESSERA_GLSL == 300
#if BRICKS_TEXEL == 2
  // Two bytes filtered apart are each rounded to 8 bits by GPUs that filter
  // 8-bit textures in fixed point (llvmpipe): a value crossing a multiple of
  // 256 would be off by up to 128. The atlas is NEAREST and the 8 corners
  // are recombined first, then interpolated.
  vec3 c = texel - 0.5;
  vec3 f = c - floor(c);
  ivec3 i = ivec3(floor(c));
  float v000 = BRICKS_VALUE(texelFetch(u_layoutAtlas, i, 0));
  float v100 = BRICKS_VALUE(texelFetch(u_layoutAtlas, i + ivec3(1, 0, 0), 0));
  float v010 = BRICKS_VALUE(texelFetch(u_layoutAtlas, i + ivec3(0, 1, 0), 0));
  float v110 = BRICKS_VALUE(texelFetch(u_layoutAtlas, i + ivec3(1, 1, 0), 0));
  float v001 = BRICKS_VALUE(texelFetch(u_layoutAtlas, i + ivec3(0, 0, 1), 0));
  float v101 = BRICKS_VALUE(texelFetch(u_layoutAtlas, i + ivec3(1, 0, 1), 0));
  float v011 = BRICKS_VALUE(texelFetch(u_layoutAtlas, i + ivec3(0, 1, 1), 0));
  float v111 = BRICKS_VALUE(texelFetch(u_layoutAtlas, i + ivec3(1, 1, 1), 0));
  v = mix(mix(mix(v000, v100, f.x), mix(v010, v110, f.x), f.y),
          mix(mix(v001, v101, f.x), mix(v011, v111, f.x), f.y), f.z);
#else
  v = BRICKS_VALUE(texture(u_layoutAtlas, texel / u_layoutAtlasTexels));
#endif
#else
  float zc = texel.z - 0.5;
  float z0 = floor(zc);
#if BRICKS_TEXEL == 3
  // As for RG8 above: NEAREST, each corner recombined, then interpolated.
  vec2 c = texel.xy - 0.5;
  vec2 f = c - floor(c);
  vec2 a = floor(c) + 0.5;  // the lower corner's texel centre
  vec2 dx = vec2(1.0, 0.0);
  vec2 dy = vec2(0.0, 1.0);
  float t = b.atlas;
  float s0 = mix(mix(layoutAtlasSlice(t, z0, a), layoutAtlasSlice(t, z0, a + dx), f.x),
                 mix(layoutAtlasSlice(t, z0, a + dy), layoutAtlasSlice(t, z0, a + 1.0), f.x),
                 f.y);
  float s1 =
      mix(mix(layoutAtlasSlice(t, z0 + 1.0, a), layoutAtlasSlice(t, z0 + 1.0, a + dx), f.x),
          mix(layoutAtlasSlice(t, z0 + 1.0, a + dy), layoutAtlasSlice(t, z0 + 1.0, a + 1.0), f.x),
          f.y);
  v = mix(s0, s1, zc - z0);
#else
  v = mix(layoutAtlasSlice(b.atlas, z0, texel.xy), layoutAtlasSlice(b.atlas, z0 + 1.0, texel.xy),
          zc - z0);
#endif
#endif
  return mix(v, b.constant, b.isConstant);
}

float sampleVolume(vec3 p) {
  vec3 q = clamp(p, 0.0, 1.0);
  BrickPage b = brickPage(q * u_layoutDims0);
  return brickValue(b, clamp(q * b.scale + b.offset, b.lo, b.hi));
}

#ifdef LAYOUT_BRICK_WALK
// The brick walk (render/raycast.frag.glsl): the ray caster calls
// layoutEnterCell when its ray enters a level-0 brick cell, reading the page
// once, and samples inside that cell with sampleVolumeInCell, which maps p
// straight into the slot: one multiply-add and the atlas fetch a sample. A
// sample lies in the cell's brick up to rounding, which the apron covers: no
// clamp; a filtered ES 3 atlas takes normalised coordinates directly.
BrickPage walkPage;
#if TESSERA_GLSL == 300 && BRICKS_TEXEL < 2
vec3 walkScale;
vec3 walkOffset;
#endif

vec3 layoutWalkCellsPerUnit() {
  return u_layoutDims0 / u_layoutBrick;
}

#if BRICKS_WALK_PAGES
// ES 3, filtered atlas, a pyramid of equal factors per axis: a float page
// per cell holds the walk's map directly, xyz = the offset into the atlas
// (normalised), w = 1 / s_l (0: a transparent cell, x its constant).
uniform highp sampler2D u_layoutWalkPages;
uniform vec3 u_layoutWalkScale0;  // level-0 voxels / atlas texels
float walkConstant;
float walkIsConstant;

vec3 layoutEnterCell(vec3 p) {
  vec3 x0 = clamp(p, 0.0, 1.0) * u_layoutDims0;
  vec3 cell = min(floor(x0 / u_layoutBrick), u_layoutCells - 1.0);
  vec4 w = texelFetch(u_layoutWalkPages, ivec2(pageTexel(cell)), 0);
  walkIsConstant = step(w.w, 0.0);
  walkConstant = w.x;
  walkScale = u_layoutWalkScale0 * w.w;
  walkOffset = w.xyz;
  return cell;
}

float layoutCellTransparent() {
  return walkIsConstant;
}

float sampleVolumeInCell(vec3 p) {
  return mix(BRICKS_VALUE(texture(u_layoutAtlas, p * walkScale + walkOffset)), walkConstant,
             walkIsConstant);
}
#else

// Reads the page of the cell holding p; returns the cell.
vec3 layoutEnterCell(vec3 p) {
  vec3 x0 = clamp(p, 0.0, 1.0) * u_layoutDims0;
  walkPage = brickPage(x0);
#if TESSERA_GLSL == 300 && BRICKS_TEXEL < 2
  walkScale = walkPage.scale / u_layoutAtlasTexels;
  walkOffset = walkPage.offset / u_layoutAtlasTexels;
#endif
  return min(floor(x0 / u_layoutBrick), u_layoutCells - 1.0);
}

// 1.0 when the cell entered last is transparent under the transfer function
// (its page holds a constant the TF hides): the walk crosses it in one step.
float layoutCellTransparent() {
  return walkPage.isConstant;
}

float sampleVolumeInCell(vec3 p) {
#if TESSERA_GLSL == 300 && BRICKS_TEXEL < 2
  return mix(BRICKS_VALUE(texture(u_layoutAtlas, p * walkScale + walkOffset)), walkPage.constant,
             walkPage.isConstant);
#else
  return brickValue(walkPage, p * walkPage.scale + walkPage.offset);
#endif
}
#endif
#endif
