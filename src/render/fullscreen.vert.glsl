// One triangle that covers the viewport; the fragment shader does the work.
#if TESSERA_GLSL == 300
in vec2 a_position;
#else
attribute vec2 a_position;
#endif

void main() { gl_Position = vec4(a_position, 0.0, 1.0); }
