// One sample as every layout-based technique takes it: the layout's
// reconstruction (sampleVolume), the value window, the transfer function,
// and with SHADING the light (render/shading.glsl, from
// sampleVolumeGradient). Techniques call this instead of writing the chain
// in their main(), so a stage added here reaches all of them.
#ifdef SHADING
// Straight colour c classified at p, lit; transparent samples skip the
// gradient's fetches.
vec4 shadeSample(vec4 c, vec3 p) {
  if (c.a <= 0.0) return c;
  return vec4(shadeBlinnPhong(c.rgb, sampleVolumeGradient(p) * u_shadeGradientScale), c.a);
}
#endif

vec4 classifiedSample(vec3 p) {
  vec4 c = classify(normalizedValue(sampleVolume(p)));
#ifdef SHADING
  c = shadeSample(c, p);
#endif
  return c;
}
