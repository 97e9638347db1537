#pragma once
// A 1D table of RGBA floats (a baked transfer function, a palette) as an
// N x 1 texture, in the most precise format the device filters: RGBA16F on
// ES 3 and on ES 2 with half-float textures (8-bit opacities would lose the
// small per-sample alphas of fine steps), RGBA8 otherwise. Re-uploads in
// place while the size stays. Re-uploading it is the whole cost of a TF
// change on the post-classified and paletted paths (Moser & Weiskopf 2008,
// section 4).
#include <string>
#include <vector>

#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"

namespace tessera::gpu {

class LookupTexture {
 public:
  // `rgba` holds 4 floats per entry. Nearest by default: render/classify.glsl
  // reads two entries at texel centres and interpolates them itself.
  void upload(GlContext& context, const std::vector<float>& rgba, const std::string& label,
              Filter filter = Filter::Nearest);
  const Texture& texture() const { return texture_; }
  int entries() const { return entries_; }
  int uploads() const { return uploads_; }  // how often upload() ran (tests of TF update paths)
  std::uint64_t bytes() const { return texture_.bytes(); }

 private:
  Texture texture_;
  int entries_ = 0;
  int uploads_ = 0;
};

}  // namespace tessera::gpu
