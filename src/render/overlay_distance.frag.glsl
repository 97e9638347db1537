// The line's distance along the pixel's ray, t = |p - eye| (perspective) or
// (p - eye) . forward (orthographic), as the ray caster's t; packed as a
// 24-bit fraction of u_distanceScale into RGB (exact: 2^24 fits a float's
// mantissa). Alpha 1 marks a line pixel.
#if TESSERA_GLSL == 300
in vec4 v_color;
in vec3 v_world;
#else
varying vec4 v_color;
varying vec3 v_world;
#endif
uniform vec3 u_eye;
uniform vec3 u_forward;
uniform int u_ortho;
uniform float u_distanceScale;

void main() {
  vec3 d = v_world - u_eye;
  float t = u_ortho == 1 ? dot(d, u_forward) : length(d);
  float v = floor(clamp(t / u_distanceScale, 0.0, 1.0) * 16777215.0 + 0.5);
  float r = floor(v / 65536.0);
  float g = floor((v - r * 65536.0) / 256.0);
  float b = v - r * 65536.0 - g * 256.0;
  FRAG_COLOR = vec4(r / 255.0, g / 255.0, b / 255.0, 1.0);
}
