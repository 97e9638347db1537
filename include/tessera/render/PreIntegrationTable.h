#pragma once
// The pre-integration table on the GPU (reference/PreIntegration.h): N x N
// entries over (front, back) normalised values, straight colour and the
// opacity of one base step, sampled bilinearly by render/classify.glsl's
// classifySegment(). Stored in the most precise format the device filters:
// RGBA16F on ES 3, half floats on ES 2 where OES_texture_half_float is there,
// RGBA8 otherwise. Rebuilt only when the TF, opacity scale, step or size
// changes; a rebuild is the O(N^2) table from the TF's integral functions
// plus the upload, both timed.
#include <string>
#include <vector>

#include "tessera/core/TransferFunction.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"

namespace tessera::render {

// Replaces each entry's opacity a (every 4th float of straight RGBA) by
// log2(1 - a), at least -24 (a = 1 - 2^-24: opaque for 8-bit output): the
// tables raycast.frag.glsl reads with LOG_TRANSMITTANCE (this 2D one and the
// 1D TF table).
void toLog2Transmittance(std::vector<float>& rgba);

class PreIntegrationTable {
 public:
  static constexpr int kDefaultEntries = 256;

  // Makes the table hold `tf` for segments of `length` world units; returns
  // whether it had to rebuild.
  bool update(gpu::GlContext& context, const TransferFunction& tf, double opacityScale,
              double length, int entries = kDefaultEntries);
  // RGBA8 even where half floats filter (what ES 2 devices without
  // OES_texture_half_float get; for tests of that path).
  void setEightBit(bool eightBit) {
    if (eightBit != eightBit_) key_.clear();
    eightBit_ = eightBit;
  }
  // Whether the texels are (half) floats in `context`: they can hold an
  // opacity as log2 of the transmittance (negative).
  bool floatTexels(const gpu::GlContext& context) const;
  // Upload opacity as log2(1 - a) (at least -24) instead of a, for
  // raycast.frag.glsl's LOG_TRANSMITTANCE; only with floatTexels(). values()
  // keeps a.
  void setLogTransmittance(bool on) {
    if (on != logTransmittance_) key_.clear();
    logTransmittance_ = on;
  }

  const gpu::Texture& texture() const { return texture_; }
  int entries() const { return entries_; }
  std::uint64_t bytes() const { return texture_.bytes(); }
  int builds() const { return builds_; }
  // The last rebuild: integral functions + N^2 entries on the CPU, and the upload.
  double lastBuildMs() const { return buildMs_; }
  double lastUploadMs() const { return uploadMs_; }
  // The table as last built (4 floats per entry), for tests.
  const std::vector<float>& values() const { return values_; }

 private:
  gpu::Texture texture_;
  std::string key_;
  int entries_ = 0;
  int builds_ = 0;
  bool eightBit_ = false;
  bool logTransmittance_ = false;
  double buildMs_ = 0.0;
  double uploadMs_ = 0.0;
  std::vector<float> values_;
};

}  // namespace tessera::render
