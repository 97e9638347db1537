#pragma once
// Volumes, contexts and error measures the layout tests share.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/layout/Layout.h"
#include "tessera/reference/ReferenceRaycaster.h"

namespace tessera::test {

// A volume whose every voxel differs from its neighbours, so an addressing
// slip of one voxel along any axis shows; wider types also use the bits
// above 8 (and the sign, for I16).
inline Volume addressPattern(glm::ivec3 d, ScalarType type) {
  Volume v = Volume::allocate(d, type);
  for (int z = 0; z < d.z; ++z) {
    for (int y = 0; y < d.y; ++y) {
      for (int x = 0; x < d.x; ++x) {
        const double u8 = (x * 7 + y * 31 + z * 101) % 256;
        double value = u8;
        if (type == ScalarType::U16) value = u8 * 200.0 + x;
        if (type == ScalarType::I16) value = u8 * 100.0 - 12000.0 + y;
        if (type == ScalarType::F32) value = u8 / 255.0 - 0.5 + z * 1e-3;
        v.setValueAtIndex(v.index(x, y, z), value);
      }
    }
  }
  return v;
}

inline std::unique_ptr<gpu::GlContext> es2Context() {
  gpu::GlContext::Options options;
  options.api = gpu::ApiLevel::Gles2;
  return gpu::GlContext::createHeadless(options);
}

// Worst |GPU - CPU trilinear| in raw units, over `positions` and the values
// the layout sampled there (`stored`, in its stored units).
inline double worstTrilinearError(const Volume& v, const layout::Layout& l,
                                  const std::vector<glm::vec3>& positions,
                                  const std::vector<float>& stored) {
  const layout::ValueMapping m = l.rawFromStored();
  double worst = 0.0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double gpu = m.scale * stored[i] + m.offset;
    worst = std::max(worst, std::abs(gpu - sampleTrilinear(v, glm::dvec3(positions[i]))));
  }
  return worst;
}

}  // namespace tessera::test
