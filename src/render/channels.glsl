// Several channels in one ray march (docs/channels.md), with a layout that
// defines CHANNELS (layout/channels.glsl: sampleChannels and the
// u_layoutChannel* uniforms). Additive: per channel opacity a_i from the
// transfer function's (step-corrected) opacity of its windowed value, the
// sample's premultiplied colour sum(a_i col_i) clamped to its opacity
// 1 - prod(1 - a_i). Max: per channel maximum along the ray, colours summed.
#ifdef CHANNELS
vec4 channelOpacities(vec4 n) {
  return vec4(classify(n.x).a, classify(n.y).a, classify(n.z).a, classify(n.w).a);
}

// The channels' combined colour at p, straight (as classify() returns).
vec4 classifiedChannels(vec3 p) {
  vec4 n0;
  vec4 n1;
  sampleChannels(p, n0, n1);
  vec4 a0 = channelOpacities(n0) * u_layoutChannelOn0;
  vec4 a1 = vec4(0.0);
  if (u_layoutChannelTextures > 1.5) a1 = channelOpacities(n1) * u_layoutChannelOn1;
  vec3 premultiplied = vec3(dot(a0, u_layoutChannelRed0) + dot(a1, u_layoutChannelRed1),
                            dot(a0, u_layoutChannelGreen0) + dot(a1, u_layoutChannelGreen1),
                            dot(a0, u_layoutChannelBlue0) + dot(a1, u_layoutChannelBlue1));
  vec4 t0 = 1.0 - a0;
  vec4 t1 = 1.0 - a1;
  float alpha = 1.0 - t0.x * t0.y * t0.z * t0.w * t1.x * t1.y * t1.z * t1.w;
  premultiplied = min(premultiplied, vec3(alpha));
  return alpha > 0.0 ? vec4(premultiplied / alpha, alpha) : vec4(0.0);
}

vec4 channelPeak0 = vec4(0.0);  // the ray's maxima so far (MODE_MIP)
vec4 channelPeak1 = vec4(0.0);

// Takes the sample at p into the per channel maxima; returns a value >= 0
// (the ray's maxValue, which says that a sample was taken).
float channelsTakeMax(vec3 p) {
  vec4 n0;
  vec4 n1;
  sampleChannels(p, n0, n1);
  channelPeak0 = max(channelPeak0, n0 * u_layoutChannelOn0);
  channelPeak1 = max(channelPeak1, n1 * u_layoutChannelOn1);
  return 0.0;
}

// The projection's pixel: each channel's colour times its maximum, summed,
// opaque.
vec4 channelsMaxColor() {
  vec3 rgb = vec3(dot(channelPeak0, u_layoutChannelRed0) + dot(channelPeak1, u_layoutChannelRed1),
                  dot(channelPeak0, u_layoutChannelGreen0) + dot(channelPeak1, u_layoutChannelGreen1),
                  dot(channelPeak0, u_layoutChannelBlue0) + dot(channelPeak1, u_layoutChannelBlue1));
  return vec4(min(rgb, vec3(1.0)), 1.0);
}
#endif
