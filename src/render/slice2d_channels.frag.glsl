// Axis-aligned slices of several channels (render/Slice2DRenderer.h,
// docs/channels.md): each stack plane lies on a voxel plane, so the layout's
// sampleChannels() there reads what a 2D slice of the channels would hold
// (bilinear within the plane). Additive: the ray caster's
// classifiedChannels(), its opacity corrected for the distance the ray
// travels between drawn planes as for one volume. Max: the windowed values,
// channels 0-3 in one pass and 4-5 with the hit flag in a second
// (u_channelGroup), which render/slice_channels_resolve.frag.glsl colours.
// Additive slabs: a quad stands for SLAB_PLANES consecutive planes (1 but
// on an 8-bit accumulation target, render/Slice2DRenderer.h); its fragment
// takes them where its view ray crosses them, u_planeStep apart along the
// axis, composites them front to back at float precision and blends once,
// dithered as slice3d.frag.glsl does. Samples off the volume (the slab's
// widened quad, the last slab's planes past the stack) keep alpha 0.
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
#ifndef SLAB_PLANES
#define SLAB_PLANES 1
#endif
uniform float u_planeStep;  // world distance between drawn planes along the axis, front to back

void main() {
#ifdef MODE_MIP
  vec3 p = clamp(v_world * u_invExtent + 0.5, 0.0, 1.0);
  vec4 n0;
  vec4 n1;
  sampleChannels(p, n0, n1);
  if (u_channelGroup > 0.5) {
    FRAG_COLOR = vec4(n1.xy * u_layoutChannelOn1.xy, 0.0, 1.0);
  } else {
    FRAG_COLOR = n0 * u_layoutChannelOn0;
  }
#else
  vec3 dir = u_ortho > 0.5 ? u_forward : normalize(v_world - u_eye);
  float cosine = max(abs(dot(dir, u_axis)), 1e-3);
  float ratio = u_gap / cosine;
  // The ray meets the next plane |u_planeStep| / cos further on.
  vec3 rayStep = dir * (abs(u_planeStep) / cosine) * u_invExtent;
  vec3 p0 = v_world * u_invExtent + 0.5;
  vec4 acc = vec4(0.0);
  for (int j = 0; j < SLAB_PLANES; j++) {
    vec3 p = p0 + float(j) * rayStep;
    vec3 inside3 = step(vec3(0.0), p) * step(p, vec3(1.0));
    vec4 c = classifiedChannels(clamp(p, 0.0, 1.0));
    c.rgb *= c.a;
    c = correctOpacity(c * (inside3.x * inside3.y * inside3.z), ratio);
    // Front to back in premultiplied colour, as the accumulator blends.
    acc += (1.0 - acc.a) * c;
  }
#ifdef DITHER_8BIT
  acc = ditherTo8Bits(acc, v_tileOrigin.x);  // slice_opacity.glsl, as slice3d does
#endif
  FRAG_COLOR = acc;
#endif
}
