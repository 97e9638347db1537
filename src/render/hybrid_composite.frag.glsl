// Full-resolution composite of the hybrid compositor: the bilinearly
// upscaled volume layer (colour over black, opacity estimate) over the line
// layer or the background. The line layer says per pixel where its line
// lies (overlay_color.frag.glsl): alpha 1, in front of the volume, drawn
// unattenuated; alpha 0.5, seen through the volume: out = C + (1 - alpha) *
// line. Branch-free: a line pixel costs what any other does.
uniform sampler2D u_volume;
uniform sampler2D u_lineColor;
uniform float u_hasLines;
uniform vec4 u_background;
uniform vec2 u_origin;    // the viewport's lower-left corner in window pixels
uniform vec2 u_viewport;  // its size

void main() {
  vec2 uv = (gl_FragCoord.xy - u_origin) / u_viewport;
  vec4 v = TEX2D(u_volume, uv);
  vec4 line = TEX2D(u_lineColor, uv) * u_hasLines;
  float front = step(0.75, line.a);
  float behind = step(0.25, line.a) - front;
  vec3 under = mix(u_background.rgb, line.rgb, behind);
  float underAlpha = mix(u_background.a, 1.0, behind);
  vec4 composed = vec4(v.rgb + (1.0 - v.a) * under, v.a + (1.0 - v.a) * underAlpha);
  FRAG_COLOR = mix(composed, vec4(line.rgb, 1.0), front);
}
