// The zoom swap's cross-fade (viewer/ZoomSwap.h): the previous stage's image
// drawn over the new stage's frame with straight alpha at its remaining
// weight. GLSL 100 and 300 alike, so the fade works on ES 2 / WebGL 1.
uniform sampler2D u_old;
uniform vec2 u_origin;  // the view's lower-left pixel in the target
uniform vec2 u_size;    // the view's size in pixels
uniform float u_weight;

void main() {
  vec2 uv = (gl_FragCoord.xy - u_origin) / u_size;
  FRAG_COLOR = vec4(TEX2D(u_old, uv).rgb, u_weight);
}
