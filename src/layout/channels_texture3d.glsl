// Several channels for ChannelLayout on ES 3: four channels per RGBA texel of
// a 3D texture (Noguera & Jimenez 2012's RGBA packing, one voxel's channels
// in one texel), channels 0-3 in u_layoutChannels0, 4-5 in
// u_layoutChannels1; one hardware-trilinear fetch per four channels.
// layout/channels.glsl follows with what both storages share.
#define CHANNELS 1
uniform highp sampler3D u_layoutChannels0;
uniform highp sampler3D u_layoutChannels1;

vec4 layoutChannelTexel0(vec3 p) { return texture(u_layoutChannels0, p); }
vec4 layoutChannelTexel1(vec3 p) { return texture(u_layoutChannels1, p); }
