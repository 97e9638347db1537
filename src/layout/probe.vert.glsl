// LayoutProbe without float render targets (ES 2): one point per position,
// drawn at its own pixel, the position passed as a float vertex attribute —
// exact, and constant over the point's single fragment.
#if TESSERA_GLSL == 300
in vec2 a_position;  // clip-space centre of the pixel
in vec3 a_probe;     // position in [0,1]^3
out vec3 v_probe;
#else
attribute vec2 a_position;
attribute vec3 a_probe;
varying vec3 v_probe;
#endif

void main() {
  v_probe = a_probe;
  gl_Position = vec4(a_position, 0.0, 1.0);
  gl_PointSize = 1.0;
}
