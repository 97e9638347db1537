#pragma once
// Transfer functions the image tests share.
#include "tessera/core/TransferFunction.h"

namespace tessera::test {

// Grey-to-orange ramp with enough opacity that small phantoms show their
// inner structure (and that differences between paths show in the pixels).
inline TransferFunction visibleTf() {
  TransferFunction tf;
  tf.addColor(0.0, {0.0, 0.0, 0.0});
  tf.addColor(0.5, {0.9, 0.6, 0.3});
  tf.addColor(1.0, {1.0, 1.0, 1.0});
  tf.addOpacity(0.02, 0.0);
  tf.addOpacity(0.3, 0.15);
  tf.addOpacity(1.0, 0.4);
  return tf;
}

}  // namespace tessera::test
