// Full-screen triangle that also hands the fragment its texture coordinate.
#if TESSERA_GLSL == 300
in vec2 a_position;
out vec2 v_uv;
#else
attribute vec2 a_position;
varying vec2 v_uv;
#endif

void main() {
  v_uv = a_position * 0.5 + 0.5;
  gl_Position = vec4(a_position, 0.0, 1.0);
}
