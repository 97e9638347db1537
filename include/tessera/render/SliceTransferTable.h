#pragma once
// A transfer-function table (the post-classification LUT or the palette of
// the paletted slice path) as a one-row texture: RGBA16F where the device
// filters half floats (all of ES 3, ES 2 with OES_texture_half_float_linear),
// RGBA8 otherwise. Re-uploading it is the whole cost of a TF change on the
// post-classified and paletted paths (Moser & Weiskopf 2008, section 4).
#include <cstdint>
#include <string>
#include <vector>

#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"

namespace tessera::render {

class SliceTransferTable {
 public:
  // `rgba`: 4 floats per entry. Creates the texture on first use or when the
  // entry count changes, else replaces its contents.
  void upload(gpu::GlContext& context, const std::vector<float>& rgba, const std::string& label);
  const gpu::Texture& texture() const { return texture_; }
  int entries() const { return entries_; }
  std::uint64_t uploads() const { return uploads_; }

 private:
  gpu::Texture texture_;
  int entries_ = 0;
  std::uint64_t uploads_ = 0;
};

}  // namespace tessera::render
