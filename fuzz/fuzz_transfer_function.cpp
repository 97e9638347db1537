// libFuzzer target: TransferFunction::fromJson, and bake() on what it accepts
// (the accepted points must be safe to evaluate and tabulate).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "FuzzTarget.h"
#include "tessera/core/TransferFunction.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const TransferFunction tf = TransferFunction::fromJson(text, "fuzz");
  const std::vector<float> table = tf.bake(256, 0.5, 1.0);
  for (const float v : table) {
    // fromJson promises colours and opacities in [0, 1].
    if (!(v >= 0.0f && v <= 1.0f)) {
      std::fprintf(stderr, "bake() produced %g from an accepted transfer function\n", v);
      std::abort();
    }
  }
}
