// Overlay lines (bounding box, axes) in world coordinates.
uniform mat4 u_viewProjection;
#if TESSERA_GLSL == 300
in vec3 a_position;
in vec4 a_color;
out vec4 v_color;
#else
attribute vec3 a_position;
attribute vec4 a_color;
varying vec4 v_color;
#endif

void main() {
  v_color = a_color;
  gl_Position = u_viewProjection * vec4(a_position, 1.0);
}
