// Overlay lines in world coordinates; the world position goes to the
// fragment shader, which needs the distance along the pixel's ray.
uniform mat4 u_viewProjection;
#if TESSERA_GLSL == 300
in vec3 a_position;
in vec4 a_color;
out vec4 v_color;
out vec3 v_world;
#else
attribute vec3 a_position;
attribute vec4 a_color;
varying vec4 v_color;
varying vec3 v_world;
#endif

void main() {
  v_color = a_color;
  v_world = a_position;
  gl_Position = u_viewProjection * vec4(a_position, 1.0);
}
