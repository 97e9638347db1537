#include "tessera/render/PreIntegrationTable.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <sstream>

#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/gpu/DeviceProfile.h"
#include "tessera/gpu/TexelFormat.h"
#include "tessera/reference/PreIntegration.h"

namespace tessera::render {

void toLog2Transmittance(std::vector<float>& rgba) {
  for (std::size_t i = 3; i < rgba.size(); i += 4) {
    rgba[i] = static_cast<float>(
        std::log2(std::max(1.0 - static_cast<double>(rgba[i]), std::exp2(-24.0))));
  }
}

bool PreIntegrationTable::floatTexels(const gpu::GlContext& context) const {
  return !eightBit_ && (context.caps().api == gpu::ApiLevel::Gles3 ||
                        gpu::DeviceLimits::of(context.caps()).halfFloatTextures);
}

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
  if (floatTexels(context)) {
    format = context.caps().api == gpu::ApiLevel::Gles3 ? gpu::TexelFormat::RGBA16F
                                                        : gpu::TexelFormat::RgbaHalfUnsized;
  }
  if (logTransmittance_ && !floatTexels(context)) {
    throw Error("pre-integration table: log transmittance needs float texels");
  }
  std::vector<float> logValues;
  if (logTransmittance_) {
    logValues = values_;
    toLog2Transmittance(logValues);
  }
  const std::vector<float>& uploaded = logTransmittance_ ? logValues : values_;
  const std::vector<std::uint16_t> halves = format == gpu::TexelFormat::RgbaHalfUnsized
                                                ? gpu::packHalves(uploaded)
                                                : std::vector<std::uint16_t>();
  const std::vector<std::uint8_t> bytes =
      format == gpu::TexelFormat::Rgba8Unsized || format == gpu::TexelFormat::RGBA8
          ? gpu::packUnorm8(uploaded)
          : std::vector<std::uint8_t>();
  const void* data = format == gpu::TexelFormat::RgbaHalfUnsized
                         ? static_cast<const void*>(halves.data())
                     : !bytes.empty() ? static_cast<const void*>(bytes.data())
                                      : static_cast<const void*>(uploaded.data());
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
