// What ChannelLayout's two storages share (after channels_texture3d.glsl or
// channels_mosaic.glsl, which define layoutChannelTexel0/1): each channel's
// window as n = clamp(stored * scale + bias, 0, 1), its visibility and its
// colour, four channels per vec4 (docs/channels.md).
uniform float u_layoutChannelTextures;  // 1 (channels 0-3) or 2 (0-5)
uniform vec4 u_layoutChannelScale0;
uniform vec4 u_layoutChannelScale1;
uniform vec4 u_layoutChannelBias0;
uniform vec4 u_layoutChannelBias1;
uniform vec4 u_layoutChannelOn0;  // 1: visible; 0: hidden or absent
uniform vec4 u_layoutChannelOn1;
uniform vec4 u_layoutChannelRed0;  // colours, one component per vec4
uniform vec4 u_layoutChannelRed1;
uniform vec4 u_layoutChannelGreen0;
uniform vec4 u_layoutChannelGreen1;
uniform vec4 u_layoutChannelBlue0;
uniform vec4 u_layoutChannelBlue1;

// The windowed values of channels 0-3 (n0) and 4-5 (n1) at p; the second
// texture is read only when there is one.
void sampleChannels(vec3 p, out vec4 n0, out vec4 n1) {
  n0 = clamp(layoutChannelTexel0(p) * u_layoutChannelScale0 + u_layoutChannelBias0, 0.0, 1.0);
  n1 = vec4(0.0);
  if (u_layoutChannelTextures > 1.5) {
    n1 = clamp(layoutChannelTexel1(p) * u_layoutChannelScale1 + u_layoutChannelBias1, 0.0, 1.0);
  }
}

// The seam's scalar (gradients, probes): channel 0's stored value (the
// bricks layout's own sampleVolume reads it already).
#ifndef LAYOUT_HAS_SAMPLE_VOLUME
float sampleVolume(vec3 p) { return layoutChannelTexel0(p).r; }
#endif
