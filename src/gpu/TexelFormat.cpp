#include "tessera/gpu/TexelFormat.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/packing.hpp>

#include "gpu/GlFormats.h"

namespace tessera::gpu {

GlFormat glFormat(TexelFormat f) {
  switch (f) {
    case TexelFormat::R8:
      return {GL_R8, GL_RED, GL_UNSIGNED_BYTE, 1, 1};
    case TexelFormat::R16:
      return {GL_R16_EXT, GL_RED, GL_UNSIGNED_SHORT, 2, 2};
    case TexelFormat::RGBA16:
      return {GL_RGBA16_EXT, GL_RGBA, GL_UNSIGNED_SHORT, 8, 8};
    case TexelFormat::R16F:
      return {GL_R16F, GL_RED, GL_FLOAT, 2, 4};
    case TexelFormat::R32F:
      return {GL_R32F, GL_RED, GL_FLOAT, 4, 4};
    case TexelFormat::RG8:
      return {GL_RG8, GL_RG, GL_UNSIGNED_BYTE, 2, 2};
    case TexelFormat::RGBA8:
      return {GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, 4, 4};
    case TexelFormat::RGBA16F:
      return {GL_RGBA16F, GL_RGBA, GL_FLOAT, 8, 16};
    case TexelFormat::RGBA32F:
      return {GL_RGBA32F, GL_RGBA, GL_FLOAT, 16, 16};
    case TexelFormat::Luminance8:
      return {GL_LUMINANCE, GL_LUMINANCE, GL_UNSIGNED_BYTE, 1, 1};
    case TexelFormat::LuminanceAlpha8:
      return {GL_LUMINANCE_ALPHA, GL_LUMINANCE_ALPHA, GL_UNSIGNED_BYTE, 2, 2};
    case TexelFormat::Rgba8Unsized:
      return {GL_RGBA, GL_RGBA, GL_UNSIGNED_BYTE, 4, 4};
    case TexelFormat::RgbaHalfUnsized:
      return {GL_RGBA, GL_RGBA, GL_HALF_FLOAT_OES, 8, 8};
  }
  return {GL_R8, GL_RED, GL_UNSIGNED_BYTE, 1, 1};
}

TexelFormat rgba8For(ApiLevel api) {
  return api == ApiLevel::Gles3 ? TexelFormat::RGBA8 : TexelFormat::Rgba8Unsized;
}

TexelFormat r8For(ApiLevel api) {
  return api == ApiLevel::Gles3 ? TexelFormat::R8 : TexelFormat::Luminance8;
}

std::uint64_t bytesPerTexel(TexelFormat f) {
  return glFormat(f).texelBytes;
}

std::uint64_t uploadBytesPerTexel(TexelFormat f) {
  return glFormat(f).uploadBytes;
}

const char* texelFormatName(TexelFormat f) {
  switch (f) {
    case TexelFormat::R8:
      return "R8";
    case TexelFormat::R16:
      return "R16";
    case TexelFormat::RGBA16:
      return "RGBA16";
    case TexelFormat::R16F:
      return "R16F";
    case TexelFormat::R32F:
      return "R32F";
    case TexelFormat::RG8:
      return "RG8";
    case TexelFormat::RGBA8:
      return "RGBA8";
    case TexelFormat::RGBA16F:
      return "RGBA16F";
    case TexelFormat::RGBA32F:
      return "RGBA32F";
    case TexelFormat::Luminance8:
      return "L8";
    case TexelFormat::LuminanceAlpha8:
      return "LA8";
    case TexelFormat::Rgba8Unsized:
      return "RGBA8 (ES 2)";
    case TexelFormat::RgbaHalfUnsized:
      return "RGBA16F (ES 2 half float)";
  }
  return "?";
}

std::vector<std::uint16_t> packHalves(const std::vector<float>& values) {
  std::vector<std::uint16_t> out(values.size());
  std::transform(values.begin(), values.end(), out.begin(),
                 [](float x) { return glm::packHalf1x16(x); });
  return out;
}

std::vector<std::uint8_t> packUnorm8(const std::vector<float>& values) {
  std::vector<std::uint8_t> out(values.size());
  std::transform(values.begin(), values.end(), out.begin(), [](float x) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f));
  });
  return out;
}

}  // namespace tessera::gpu
