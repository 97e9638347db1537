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
#endif
