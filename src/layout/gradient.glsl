// The seam's optional gradient: sampleVolumeGradient(p) is the derivative of
// sampleVolume() per texture-space unit (stored value per unit of p). By
// default central differences one voxel apart along each axis, through
// sampleVolume(), so it works on every layout; a layout (or reconstruction)
// with an analytic derivative defines LAYOUT_HAS_GRADIENT and its own. The
// CPU twin is Reconstruction::gradient (reference/Reconstruction.h).
#ifndef LAYOUT_HAS_GRADIENT
uniform vec3 u_layoutVoxel;  // one voxel in texture space: 1 / dims

vec3 sampleVolumeGradient(vec3 p) {
  vec3 h = u_layoutVoxel;
  return vec3(sampleVolume(p + vec3(h.x, 0.0, 0.0)) - sampleVolume(p - vec3(h.x, 0.0, 0.0)),
              sampleVolume(p + vec3(0.0, h.y, 0.0)) - sampleVolume(p - vec3(0.0, h.y, 0.0)),
              sampleVolume(p + vec3(0.0, 0.0, h.z)) - sampleVolume(p - vec3(0.0, 0.0, h.z))) /
         (2.0 * h);
}
#endif
