// Resolve pass of slice3d's channel maxima (docs/channels.md, max mode):
// the maxima of channels 0-3 (u_peaks0) and 4-5 (u_peaks1.xy, whose alpha
// says a slice met the volume), coloured and summed by channelsMaxColor()
// (render/channels.glsl) as the ray caster's per channel MIP, opaque where a
// slice met the volume, then the background as in slice_resolve.frag.glsl.
uniform sampler2D u_peaks0;
uniform sampler2D u_peaks1;
uniform vec2 u_viewport;
uniform vec4 u_background;  // premultiplied

void main() {
  vec2 uv = gl_FragCoord.xy / u_viewport;
  vec4 second = TEX2D(u_peaks1, uv);
  vec4 acc = vec4(0.0);
  if (second.a > 0.5) {
    channelPeak0 = TEX2D(u_peaks0, uv);
    channelPeak1 = vec4(second.xy, 0.0, 0.0);
    acc = channelsMaxColor();
  }
  FRAG_COLOR = vec4(acc.rgb + (1.0 - acc.a) * u_background.rgb,
                    acc.a + (1.0 - acc.a) * u_background.a);
}
