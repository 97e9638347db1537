// The line's colour, opaque.
#if TESSERA_GLSL == 300
in vec4 v_color;
in vec3 v_world;
#else
varying vec4 v_color;
varying vec3 v_world;
#endif

void main() { FRAG_COLOR = vec4(v_color.rgb, 1.0); }
