#pragma once
// The value mapping of the layouts that keep 8-bit volumes as their bytes
// and normalise any other type over its value range (mosaic, packed-mosaic).
#include "tessera/core/Volume.h"
#include "tessera/layout/Layout.h"

namespace tessera::layout {

// raw = scale * stored + offset, stored in [0,1]: 0..255 for u8 volumes,
// min..max of the value range otherwise (a flat volume keeps width 1).
inline ValueMapping normalisedMapping(const Volume& volume) {
  if (volume.type() == ScalarType::U8) return {255.0, 0.0};
  const ValueRange r = volume.valueRange();
  return {r.max > r.min ? r.max - r.min : 1.0, r.min};
}

}  // namespace tessera::layout
