#include "tessera/gpu/LookupTexture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/TexelFormat.h"

namespace tessera::gpu {

void LookupTexture::upload(GlContext& context, const std::vector<float>& rgba,
                           const std::string& label, Filter filter) {
  const int entries = static_cast<int>(rgba.size() / 4);
  ++uploads_;
  TexelFormat format = TexelFormat::Rgba8Unsized;
  if (context.caps().api == ApiLevel::Gles3) {
    format = TexelFormat::RGBA16F;
  } else if (DeviceLimits::of(context.caps()).halfFloatTextures) {
    format = TexelFormat::RgbaHalfUnsized;
  }
  const std::vector<std::uint16_t> halves =
      format == TexelFormat::RgbaHalfUnsized ? packHalves(rgba) : std::vector<std::uint16_t>();
  const std::vector<std::uint8_t> bytes =
      format == TexelFormat::Rgba8Unsized ? packUnorm8(rgba) : std::vector<std::uint8_t>();
  const void* data = format == TexelFormat::RgbaHalfUnsized
                         ? static_cast<const void*>(halves.data())
                     : format == TexelFormat::Rgba8Unsized ? static_cast<const void*>(bytes.data())
                                                           : static_cast<const void*>(rgba.data());
  if (texture_.id() != 0 && entries == entries_ && texture_.format() == format) {
    texture_.update(data);
    texture_.setFilter(filter);
    return;
  }
  entries_ = entries;
  texture_ = Texture();  // release first: the ledger counts the new one alone
  texture_ = Texture::create2D(context.ledger(), label, format, entries, 1, data);
  // Nearest for render/classify.glsl, which interpolates between two entries
  // itself: an unfiltered fetch is much cheaper for a software rasteriser
  // such as the browsers' SwiftShader (bench/web-peers).
  texture_.setFilter(filter);
}

}  // namespace tessera::gpu
