#pragma once
// Transfer functions the image tests share, and a way to write one as its
// control points.
#include <initializer_list>

#include "tessera/core/TransferFunction.h"

namespace tessera::test {

// The transfer function with these control points, added one by one
// (addColor and addOpacity insert sorted, so the lists may be in any order).
inline TransferFunction tfFromPoints(std::initializer_list<ColorPoint> colors,
                                     std::initializer_list<OpacityPoint> opacities) {
  TransferFunction tf;
  for (const ColorPoint& c : colors) tf.addColor(c.x, c.rgb);
  for (const OpacityPoint& o : opacities) tf.addOpacity(o.x, o.alpha);
  return tf;
}

// One colour over the whole range, with these opacity points.
inline TransferFunction oneColorTf(glm::dvec3 rgb, std::initializer_list<OpacityPoint> opacities) {
  return tfFromPoints({{0.0, rgb}, {1.0, rgb}}, opacities);
}

// Grey-to-orange ramp with enough opacity that small phantoms show their
// inner structure (and that differences between paths show in the pixels).
inline TransferFunction visibleTf() {
  return tfFromPoints({{0.0, {0.0, 0.0, 0.0}}, {0.5, {0.9, 0.6, 0.3}}, {1.0, {1.0, 1.0, 1.0}}},
                      {{0.02, 0.0}, {0.3, 0.15}, {1.0, 0.4}});
}

}  // namespace tessera::test
