// Post-classification through the baked transfer function: u_tf holds
// u_tfSize entries, entry i at normalised value i/(u_tfSize-1), opacity
// already corrected for the sample distance (TransferFunction::bake).
uniform sampler2D u_tf;
uniform float u_tfSize;
uniform float u_valueScale;  // normalised = clamp(stored * scale + bias, 0, 1)
uniform float u_valueBias;

float normalizedValue(float stored) { return clamp(stored * u_valueScale + u_valueBias, 0.0, 1.0); }

vec4 classify(float n) {
  float x = (n * (u_tfSize - 1.0) + 0.5) / u_tfSize;
#if TESSERA_GLSL == 300
  return texture(u_tf, vec2(x, 0.5));
#else
  return texture2D(u_tf, vec2(x, 0.5));
#endif
}
