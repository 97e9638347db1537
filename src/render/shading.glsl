// Blinn-Phong shading of a classified sample from the gradient of the
// reconstructed field: layout-based techniques take it through the layout
// seam's sampleVolumeGradient() (render/sample.glsl: central differences
// through sampleVolume(), 6 fetches, unless the layout has an analytic
// derivative), so every layout gets it; slice2d from its stacks' neighbour
// values (render/slice2d.frag.glsl), the same differences. The CPU twin is
// shadeBlinnPhong (core/RenderSettings.h); the reference lights the same
// normals (Reconstruction::gradient). Two-sided: |N.L|, |N.H|.
#ifdef SHADING
// Stored (slice2d: normalised) value per texture-space unit -> normalised value per voxel of the
// smallest spacing, per model axis (texture space is stretched by the extent).
uniform vec3 u_shadeGradientScale;
uniform vec3 u_shadeLight;         // towards the light, model frame, unit
uniform vec3 u_shadeHalf;          // Blinn half vector, model frame, unit
uniform vec4 u_shadeCoefficients;  // ambient, diffuse, specular, shininess

// eps of kShadingGradientEpsilon: flat regions fade to ambient light.
const float kShadingEpsilonSquared = 0.0001;

vec3 shadeBlinnPhong(vec3 rgb, vec3 g) {
  vec3 n = g * inversesqrt(dot(g, g) + kShadingEpsilonSquared);
  float diffuse = abs(dot(n, u_shadeLight));
  float specular = pow(abs(dot(n, u_shadeHalf)), u_shadeCoefficients.w);
  vec3 lit = rgb * (u_shadeCoefficients.x + u_shadeCoefficients.y * diffuse) +
             vec3(u_shadeCoefficients.z * specular);
  return min(lit, vec3(1.0));
}

#ifdef GRADIENT_OPACITY
uniform vec2 u_gradientOpacity;  // low, high: |gradient| where opacity starts and is full

// Gradient-magnitude opacity modulation (core/RenderSettings.h:
// gradientOpacityFactor): homogeneous regions fade, boundaries stay.
float gradientOpacity(vec3 g) {
  return clamp((length(g) - u_gradientOpacity.x) / (u_gradientOpacity.y - u_gradientOpacity.x),
               0.0, 1.0);
}
#endif

// A classified straight-colour sample with gradient g: lit (LIGHTING; without
// it SHADING only brings the gradient for the modulation) and with
// GRADIENT_OPACITY its opacity scaled. Every technique calls this.
vec4 shadeClassified(vec4 c, vec3 g) {
#ifdef LIGHTING
  c.rgb = shadeBlinnPhong(c.rgb, g);
#endif
#ifdef GRADIENT_OPACITY
  c.a *= gradientOpacity(g);
#endif
  return c;
}
#endif
