// Clip planes and the crop box (RenderSettings::clipping): whether the sample
// at texture-space p is kept. Techniques drop the samples this rejects and
// never move the others, so a moving plane adds or removes samples only where
// it passes. The CPU twin is clipKeeps (core/RenderSettings.h).
#ifdef CLIPPING
// Half-spaces dot(xyz, p) <= w; unused ones are (0, 0, 0, 1), always kept.
uniform vec4 u_clipPlanes[6];
uniform vec3 u_cropMin;
uniform vec3 u_cropMax;

bool clipKeeps(vec3 p) {
  if (any(lessThan(p, u_cropMin)) || any(greaterThan(p, u_cropMax))) return false;
  for (int i = 0; i < 6; i++) {
    if (dot(u_clipPlanes[i].xyz, p) > u_clipPlanes[i].w) return false;
  }
  return true;
}
#endif
