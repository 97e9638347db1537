#include "tessera/render/SliceTransferTable.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/packing.hpp>

#include "gpu/gl.h"
#include "tessera/gpu/DeviceProfile.h"

namespace tessera::render {

void SliceTransferTable::upload(gpu::GlContext& context, const std::vector<float>& rgba,
                                const std::string& label) {
  const int entries = static_cast<int>(rgba.size() / 4);
  if (entries != entries_) texture_ = gpu::Texture();
  entries_ = entries;
  ++uploads_;
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context.caps());
  if (context.caps().api == gpu::ApiLevel::Gles3) {
    if (texture_.id() == 0) {
      texture_ = gpu::Texture::create2D(context.ledger(), label, GL_RGBA16F, entries, 1, GL_RGBA,
                                        GL_FLOAT, rgba.data());
    } else {
      texture_.update2D(GL_RGBA, GL_FLOAT, rgba.data());
    }
    return;
  }
  if (limits.halfFloatTextures) {
    std::vector<std::uint16_t> halves(rgba.size());
    for (std::size_t i = 0; i < rgba.size(); ++i) halves[i] = glm::packHalf1x16(rgba[i]);
    if (texture_.id() == 0) {
      texture_ = gpu::Texture::create2D(context.ledger(), label, GL_RGBA, entries, 1, GL_RGBA,
                                        GL_HALF_FLOAT_OES, halves.data(), 8);
    } else {
      texture_.update2D(GL_RGBA, GL_HALF_FLOAT_OES, halves.data());
    }
    return;
  }
  std::vector<std::uint8_t> bytes(rgba.size());
  for (std::size_t i = 0; i < rgba.size(); ++i) {
    bytes[i] = static_cast<std::uint8_t>(std::lround(std::clamp(rgba[i], 0.0f, 1.0f) * 255.0f));
  }
  if (texture_.id() == 0) {
    texture_ = gpu::Texture::create2D(context.ledger(), label, GL_RGBA, entries, 1, GL_RGBA,
                                      GL_UNSIGNED_BYTE, bytes.data());
  } else {
    texture_.update2D(GL_RGBA, GL_UNSIGNED_BYTE, bytes.data());
  }
}

}  // namespace tessera::render
