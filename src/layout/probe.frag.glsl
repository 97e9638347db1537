// LayoutProbe: one fragment per position, writes sampleVolume(position).
uniform highp sampler2D u_positions;  // RGB32F, one position per texel

void main() {
  vec3 p = texelFetch(u_positions, ivec2(gl_FragCoord.xy), 0).xyz;
  FRAG_COLOR = vec4(sampleVolume(p), 0.0, 0.0, 1.0);
}
