// View-aligned slices (render/Slice3DRenderer.h): the static quads of the
// proxy cube, in cube units (side 1, slice 0 nearest the viewer along +z),
// placed by per-frame matrices. The texture matrix is the rotation that
// keeps the slices facing the viewer (Noguera et al. 2012, section 3.2).
#if TESSERA_GLSL == 300
in vec3 a_position;
out vec3 v_texCoord;
out vec3 v_view;
out float v_slab;
#else
attribute vec3 a_position;
varying vec3 v_texCoord;
varying vec3 v_view;
varying float v_slab;
#endif
uniform mat4 u_cubeToClip;
uniform mat4 u_cubeToTexture;
uniform mat4 u_cubeToView;
uniform float u_slabsPerCube;  // N / K: a slab quad lies at 0.5 - z = (slab + 0.5 / K) / this

void main() {
  vec4 p = vec4(a_position, 1.0);
  v_texCoord = (u_cubeToTexture * p).xyz;
  v_view = (u_cubeToView * p).xyz;
  v_slab = (0.5 - a_position.z) * u_slabsPerCube;  // its index + 0.5 / K
  gl_Position = u_cubeToClip * p;
}
