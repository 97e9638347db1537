// Full-resolution composite of the hybrid compositor: the bilinearly
// upscaled volume layer (colour over black, opacity estimate) over the line
// layer or the background. A line nearer than the pixel's ray enters the
// volume box is in front and drawn unattenuated; any other line is seen
// through the volume: out = C + (1 - alpha) * line.
uniform sampler2D u_volume;
uniform sampler2D u_lineColor;
uniform sampler2D u_lineDistance;
uniform float u_hasLines;
uniform float u_distanceScale;
uniform float u_frontTolerance;  // world units
uniform vec4 u_background;
uniform vec2 u_origin;  // the viewport's lower-left corner in window pixels

float lineDistance(vec2 uv) {
  vec3 p = floor(TEX2D(u_lineDistance, uv).rgb * 255.0 + 0.5);
  return (p.r * 65536.0 + p.g * 256.0 + p.b) / 16777215.0 * u_distanceScale;
}

void main() {
  vec2 uv = (gl_FragCoord.xy - u_origin) / u_viewport;
  vec4 v = TEX2D(u_volume, uv);
  vec3 under = u_background.rgb;
  float underAlpha = u_background.a;
  if (u_hasLines > 0.5) {
    vec4 line = TEX2D(u_lineColor, uv);
    if (line.a > 0.5) {
      vec3 ro;
      vec3 rd;
      cameraRay(uv * 2.0 - 1.0, ro, rd);
      vec2 range = intersectUnitBox(ro / u_extent + 0.5, safeInverse(rd / u_extent));
      float t = lineDistance(uv);
      if (range.x >= range.y || t <= max(range.x, 0.0) + u_frontTolerance) {
        FRAG_COLOR = vec4(line.rgb, 1.0);
        return;
      }
      under = line.rgb;
      underAlpha = 1.0;
    }
  }
  FRAG_COLOR = vec4(v.rgb + (1.0 - v.a) * under, v.a + (1.0 - v.a) * underAlpha);
}
