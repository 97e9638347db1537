// View-aligned slices: one sample per fragment through the layout's
// sampleVolume(), classified through the TF table baked for the slice
// spacing and corrected for the perspective ray's longer path between the
// planes. Outside the volume the fragment keeps alpha 0 instead of
// discarding (discard is slow on tiled mobile GPUs; Noguera et al. 2012).
// With CHANNELS (docs/channels.md) classifiedSample() combines the channels
// as the ray caster does; their MIP writes the per channel maxima, channels
// 0-3 in one pass and 4-5 with the hit flag in a second (u_channelGroup),
// which render/slice_channels_resolve.frag.glsl colours.
#if TESSERA_GLSL == 300
in vec3 v_texCoord;
in vec3 v_view;
#else
varying vec3 v_texCoord;
varying vec3 v_view;
#endif
uniform float u_ortho;
#if defined(CHANNELS) && defined(MODE_MIP)
uniform float u_channelGroup;  // 0: channels 0-3; 1: channels 4-5 and the hit flag
#endif

void main() {
  vec3 p = v_texCoord;
  vec3 inside3 = step(vec3(0.0), p) * step(p, vec3(1.0));
  float inside = inside3.x * inside3.y * inside3.z;
#ifdef CLIPPING
  if (!clipKeeps(p)) inside = 0.0;
#endif
  vec3 q = clamp(p, 0.0, 1.0);
#if defined(MODE_MIP) && defined(CHANNELS)
  vec4 n0;
  vec4 n1;
  sampleChannels(q, n0, n1);
  if (u_channelGroup > 0.5) {
    FRAG_COLOR = vec4(n1.xy * u_layoutChannelOn1.xy * inside, 0.0, inside);
  } else {
    FRAG_COLOR = n0 * u_layoutChannelOn0 * inside;
  }
#elif defined(MODE_MIP)
  FRAG_COLOR = vec4(normalizedValue(fieldValue(q)) * inside, 0.0, 0.0, inside);
#else
  vec4 c = classifiedSample(q);
  c = vec4(c.rgb * c.a, c.a) * inside;
  // Planes ds apart are ds / cos(theta) apart along a perspective ray.
  float ratio = u_ortho > 0.5 ? 1.0 : length(v_view) / max(-v_view.z, 1e-6);
  FRAG_COLOR = correctOpacity(c, ratio);
#endif
}
