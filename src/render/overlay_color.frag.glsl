// The line's colour, opaque, and where it lies (the hybrid composite needs
// nothing else): alpha 1 when the line is in front of the volume box along
// its pixel's ray (the composite draws it unattenuated), 0.5 when it is in
// or behind the box (seen through the volume). Decided here, once per line
// fragment, rather than by the composite for every pixel of the image. A
// line within u_frontTolerance of where the ray enters the box counts as in
// front (it lies on the box's front faces). t is the ray caster's ray
// parameter, as in overlay_distance.frag.glsl.
#if TESSERA_GLSL == 300
in vec4 v_color;
in vec3 v_world;
#else
varying vec4 v_color;
varying vec3 v_world;
#endif
uniform float u_frontTolerance;  // world units

void main() {
  vec3 ro;
  vec3 rd;
  cameraRay(gl_FragCoord.xy / u_viewport * 2.0 - 1.0, ro, rd);
  vec2 range = intersectUnitBox(ro / u_extent + 0.5, safeInverse(rd / u_extent));
  vec3 d = v_world - u_eye;
  float t = u_ortho == 1 ? dot(d, u_forward) : length(d);
  bool front = range.x >= range.y || t <= max(range.x, 0.0) + u_frontTolerance;
  FRAG_COLOR = vec4(v_color.rgb, front ? 1.0 : 0.5);
}
