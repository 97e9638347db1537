#pragma once
// Clip planes against the sample lattice. Looking down -z orthographically
// (test::topDownOrthographic), samples sit at z = top - (k + 0.5) ds, with
// ds = s.stepVoxels * spacing.z: a plane cutting away z > d between samples
// 10 and 11, moved by 0.3 ds, leaves every kept sample where it was, and a
// whole step moves the cut.
#include "tessera/core/Camera.h"
#include "tessera/core/Image.h"
#include "tessera/core/Volume.h"
#include "tessera/render/Raycaster.h"

namespace tessera::test {

struct SubStepClip {
  RenderSettings clipped;  // `s` with the plane at d = top - 10.6 ds
  Image cut;               // rendered with `clipped`
  Image nudged;            // the plane at d - 0.3 ds
  Image stepped;           // the plane at d - ds
  Image uncut;             // `s` itself
};

inline SubStepClip renderSubStepClip(render::Raycaster& caster, const Volume& v, const Camera& cam,
                                     const RenderSettings& s, int size) {
  const double ds = s.stepVoxels * v.spacing().z;
  const double top = v.extent().z / 2.0;
  auto withPlaneAt = [&](double d) {
    RenderSettings clipped = s;
    clipped.clipping.planes.push_back({{0.0, 0.0, 1.0}, d});
    return clipped;
  };
  const double d = top - 10.6 * ds;
  SubStepClip r;
  r.clipped = withPlaneAt(d);
  r.cut = caster.render(cam, r.clipped, size, size);
  r.nudged = caster.render(cam, withPlaneAt(d - 0.3 * ds), size, size);
  r.stepped = caster.render(cam, withPlaneAt(d - ds), size, size);
  r.uncut = caster.render(cam, s, size, size);
  return r;
}

}  // namespace tessera::test
