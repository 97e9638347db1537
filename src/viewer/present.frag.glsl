// Shows a technique's image on the window or canvas; bilinear filtering
// upscales the reduced-resolution frames of adaptive quality.
uniform sampler2D u_image;
#if TESSERA_GLSL == 300
in vec2 v_uv;
#else
varying vec2 v_uv;
#endif

void main() { FRAG_COLOR = vec4(TEX2D(u_image, v_uv).rgb, 1.0); }
