// View-aligned slices: each fragment of a proxy slice takes SLAB_SAMPLES
// samples along its view ray through the layout's sampleVolume(), the
// slice's own plane first and then the planes behind it, ds apart in depth,
// classified through the TF table baked for ds and corrected for the
// perspective ray's longer path between the planes, and composites them
// front to back in the shader (render/composite.glsl) before the one blend
// of the slab. With SLAB_SAMPLES 1 that is one sample a slice; an 8-bit
// accumulation target takes several (render/Slice3DRenderer.h: a slab's
// contribution is rounded to 8 bits once instead of once per plane).
// Outside the volume a sample keeps alpha 0 instead of discarding (discard
// is slow on tiled mobile GPUs; Noguera et al. 2012).
// With CHANNELS (docs/channels.md) classifiedSample() combines the channels
// as the ray caster does; their MIP writes the per channel maxima, channels
// 0-3 in one pass and 4-5 with the hit flag in a second (u_channelGroup),
// which render/slice_channels_resolve.frag.glsl colours.
#if TESSERA_GLSL == 300
in vec3 v_texCoord;
in vec3 v_view;
in float v_slab;
#else
varying vec3 v_texCoord;
varying vec3 v_view;
varying float v_slab;
#endif
uniform float u_ortho;
#if defined(CHANNELS) && defined(MODE_MIP)
uniform float u_channelGroup;  // 0: channels 0-3; 1: channels 4-5 and the hit flag
#endif
#ifndef SLAB_SAMPLES
#define SLAB_SAMPLES 1
#endif
uniform vec3 u_planeStep;      // orthographic: the texture step to the next plane
uniform vec3 u_eyeTexture;     // perspective: the eye in texture coordinates
uniform float u_planeSpacing;  // perspective: ds, the planes' distance in depth

// 1 where p lies in the volume (and the clipping keeps it), else 0.
float insideVolume(vec3 p) {
  vec3 inside3 = step(vec3(0.0), p) * step(p, vec3(1.0));
  float inside = inside3.x * inside3.y * inside3.z;
#ifdef CLIPPING
  if (!clipKeeps(p)) inside = 0.0;
#endif
  return inside;
}

void main() {
  vec3 p = v_texCoord;
#if defined(MODE_MIP)
  float inside = insideVolume(p);
  vec3 q = clamp(p, 0.0, 1.0);
#endif
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
  // Planes ds apart are ds / cos(theta) apart along a perspective ray, and
  // the ray from the eye through p meets the plane j * ds deeper at
  // p + (p - eye) * j * ds / depth.
  float ratio = 1.0;
  vec3 planeStep = u_planeStep;
  if (u_ortho < 0.5) {
    float depth = max(-v_view.z, 1e-6);
    ratio = length(v_view) / depth;
    planeStep = (p - u_eyeTexture) * (u_planeSpacing / depth);
  }
  vec4 acc = vec4(0.0);
  for (int j = 0; j < SLAB_SAMPLES; j++) {
    vec3 pj = p + float(j) * planeStep;
    vec4 c = classifiedSample(clamp(pj, 0.0, 1.0));
    c = correctOpacity(vec4(c.rgb * c.a, c.a) * insideVolume(pj), ratio);
    // Front to back in premultiplied colour, as the accumulator blends.
    acc += (1.0 - acc.a) * c;
  }
#ifdef DITHER_8BIT
  acc = ditherTo8Bits(acc, floor(v_slab));  // slice_opacity.glsl
#endif
  FRAG_COLOR = acc;
#endif
}
