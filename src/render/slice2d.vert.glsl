// Axis-aligned slices (render/Slice2DRenderer.h): one quad per voxel plane
// of a stack, in world units, with its position inside the slice (0..1) and
// its tile's corner in the atlas (texels).
#if TESSERA_GLSL == 300
in vec3 a_position;
in vec4 a_tile;
out vec3 v_world;
out vec2 v_local;
out vec2 v_tileOrigin;
#else
attribute vec3 a_position;
attribute vec4 a_tile;
varying vec3 v_world;
varying vec2 v_local;
varying vec2 v_tileOrigin;
#endif
uniform mat4 u_worldToClip;

void main() {
  v_world = a_position;
  v_local = a_tile.xy;
  v_tileOrigin = a_tile.zw;
  gl_Position = u_worldToClip * vec4(a_position, 1.0);
}
