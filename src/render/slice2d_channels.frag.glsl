// Axis-aligned slices of several channels (render/Slice2DRenderer.h,
// docs/channels.md): each stack plane lies on a voxel plane, so the layout's
// sampleChannels() there reads what a 2D slice of the channels would hold
// (bilinear within the plane). Additive: the ray caster's
// classifiedChannels(), its opacity corrected for the distance the ray
// travels between drawn planes as for one volume. Max: the windowed values,
// channels 0-3 in one pass and 4-5 with the hit flag in a second
// (u_channelGroup), which render/slice_channels_resolve.frag.glsl colours.
#if TESSERA_GLSL == 300
in vec3 v_world;
in vec2 v_local;
in vec2 v_tileOrigin;
#else
varying vec3 v_world;
varying vec2 v_local;
varying vec2 v_tileOrigin;
#endif
uniform vec3 u_invExtent;  // world (model frame, box centred at 0) -> texture space
uniform vec3 u_axis;       // the stack's axis (unit vector)
uniform float u_gap;       // distance between drawn planes / the table's distance
uniform vec3 u_eye;
uniform vec3 u_forward;
uniform float u_ortho;
#ifdef MODE_MIP
uniform float u_channelGroup;  // 0: channels 0-3; 1: channels 4-5 and the hit flag
#endif

void main() {
  vec3 p = clamp(v_world * u_invExtent + 0.5, 0.0, 1.0);
#ifdef MODE_MIP
  vec4 n0;
  vec4 n1;
  sampleChannels(p, n0, n1);
  if (u_channelGroup > 0.5) {
    FRAG_COLOR = vec4(n1.xy * u_layoutChannelOn1.xy, 0.0, 1.0);
  } else {
    FRAG_COLOR = n0 * u_layoutChannelOn0;
  }
#else
  vec4 c = classifiedChannels(p);
  c.rgb *= c.a;
  vec3 dir = u_ortho > 0.5 ? u_forward : normalize(v_world - u_eye);
  float ratio = u_gap / max(abs(dot(dir, u_axis)), 1e-3);
  FRAG_COLOR = correctOpacity(c, ratio);
#endif
}
