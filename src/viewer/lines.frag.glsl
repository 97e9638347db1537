#if TESSERA_GLSL == 300
in vec4 v_color;
#else
varying vec4 v_color;
#endif

void main() { FRAG_COLOR = v_color; }
