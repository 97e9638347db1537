// View-aligned slices (render/Slice3DRenderer.h): the static quads of the
// proxy cube, in cube units (side 1, slice 0 nearest the viewer along +z),
// placed by per-frame matrices. The texture matrix is the rotation that
// keeps the slices facing the viewer (Noguera et al. 2012, section 3.2).
#if TESSERA_GLSL == 300
in vec3 a_position;
out vec3 v_texCoord;
out vec3 v_view;
#else
attribute vec3 a_position;
varying vec3 v_texCoord;
varying vec3 v_view;
#endif
uniform mat4 u_cubeToClip;
uniform mat4 u_cubeToTexture;
uniform mat4 u_cubeToView;

void main() {
  vec4 p = vec4(a_position, 1.0);
  v_texCoord = (u_cubeToTexture * p).xyz;
  v_view = (u_cubeToView * p).xyz;
  gl_Position = u_cubeToClip * p;
}
