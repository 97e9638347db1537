#include "tessera/render/PreIntegrationTable.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "tessera/core/Timing.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/TexelFormat.h"
#include "tessera/reference/PreIntegration.h"

namespace tessera::render {

bool PreIntegrationTable::update(gpu::GlContext& context, const TransferFunction& tf,
                                 double opacityScale, double length, int entries) {
  std::ostringstream key;
  key.precision(17);
  key << length << '|' << opacityScale << '|' << entries << '|' << tf.toJson();
  if (key.str() == key_ && texture_.id() != 0) return false;

  const auto t0 = std::chrono::steady_clock::now();
  values_ = bakePreIntegrationTable(PreIntegral(tf, opacityScale), entries, length);
  buildMs_ = msSince(t0);

  const auto t1 = std::chrono::steady_clock::now();
  // 8 bits where nothing better filters (or when asked); half floats hold
  // the small opacities of short steps.
  gpu::TexelFormat format = gpu::rgba8For(context.caps().api);
  if (!eightBit_ && context.caps().api == gpu::ApiLevel::Gles3) {
    format = gpu::TexelFormat::RGBA16F;
  } else if (!eightBit_ && gpu::DeviceLimits::of(context.caps()).halfFloatTextures) {
    format = gpu::TexelFormat::RgbaHalfUnsized;
  }
  const std::vector<std::uint16_t> halves = format == gpu::TexelFormat::RgbaHalfUnsized
                                                ? gpu::packHalves(values_)
                                                : std::vector<std::uint16_t>();
  const std::vector<std::uint8_t> bytes =
      format == gpu::TexelFormat::Rgba8Unsized || format == gpu::TexelFormat::RGBA8
          ? gpu::packUnorm8(values_)
          : std::vector<std::uint8_t>();
  const void* data = format == gpu::TexelFormat::RgbaHalfUnsized
                         ? static_cast<const void*>(halves.data())
                     : !bytes.empty() ? static_cast<const void*>(bytes.data())
                                      : static_cast<const void*>(values_.data());
  if (texture_.id() != 0 && entries == entries_ && texture_.format() == format) {
    texture_.update(data);
  } else {
    texture_ = gpu::Texture();  // release first: the ledger counts the new one alone
    texture_ = gpu::Texture::create2D(context.ledger(), "pre-integration table", format, entries,
                                      entries, data);
  }
  uploadMs_ = msSince(t1);
  entries_ = entries;
  key_ = key.str();
  ++builds_;
  return true;
}

}  // namespace tessera::render
