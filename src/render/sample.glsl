// One sample as every layout-based technique takes it: the layout's
// reconstruction (sampleVolume), the value window, the transfer function.
// Techniques call this instead of writing the chain in their main(), so a
// stage added here (shading from sampleVolumeGradient) reaches all of them.
vec4 classifiedSample(vec3 p) {
  return classify(normalizedValue(sampleVolume(p)));
}
