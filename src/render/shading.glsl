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
#endif
