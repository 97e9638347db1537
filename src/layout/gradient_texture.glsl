// The seam's gradient from a precomputed texture (layout/GradientTexture.h):
// RGBA8 codes c of the per-voxel central differences, (c - 128) * step raw
// value per voxel, filtered trilinearly by the hardware; one fetch instead of
// gradient.glsl's six. u_gradientDecode turns codes into stored value per
// texture-space unit, as sampleVolumeGradient() returns. The CPU twin is
// VoxelGradientReconstruction (reference/VoxelGradients.h). GLSL ES 3.00 only.
#ifdef PRECOMPUTED_GRADIENT
#define LAYOUT_HAS_GRADIENT 1
uniform highp sampler3D u_gradientTexture;
uniform vec3 u_gradientDecode;

vec3 sampleVolumeGradient(vec3 p) {
  return (texture(u_gradientTexture, p).rgb * 255.0 - 128.0) * u_gradientDecode;
}

#ifdef GRADIENT_HOLDS_VALUES
// With 8-bit voxels in alpha (VoxelGradients::valuesInAlpha), where the
// layout stores raw / 255 on the same grid: the stored value (w) and the
// gradient (xyz) at p from one trilinear fetch.
#define LAYOUT_HAS_VALUE_AND_GRADIENT 1
vec4 sampleVolumeAndGradient(vec3 p) {
  vec4 t = texture(u_gradientTexture, p);
  return vec4((t.rgb * 255.0 - 128.0) * u_gradientDecode, t.a);
}
#endif
#endif
