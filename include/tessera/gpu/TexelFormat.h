#pragma once
// Texture formats by what they hold, not by GL enums, so that code above
// `gpu` never needs the GL headers. Each names its ES level: the sized
// formats are ES 3.0 (R16 with EXT_texture_norm16), the unsized ones ES 2.0.
// The format fixes what an upload passes (`data` layout per texel).
#include <cstdint>
#include <vector>

#include "tessera/gpu/DeviceCaps.h"

namespace tessera::gpu {

enum class TexelFormat {
  R8,               // ES 3: 1 x uint8
  R16,              // ES 3 + EXT_texture_norm16: 1 x uint16, normalised
  RGBA16,           // ES 3 + EXT_texture_norm16: 4 x uint16, normalised
  R16F,             // ES 3: upload 1 x float, stored as half
  R32F,             // ES 3: 1 x float
  RG8,              // ES 3: 2 x uint8
  RGBA8,            // ES 3: 4 x uint8
  RGBA16F,          // ES 3: upload 4 x float, stored as half
  RGBA32F,          // ES 3: 4 x float
  Luminance8,       // ES 2: 1 x uint8 (GL_LUMINANCE)
  LuminanceAlpha8,  // ES 2: 2 x uint8 (GL_LUMINANCE_ALPHA: sampled as (L, L, L, A))
  Rgba8Unsized,     // ES 2: 4 x uint8 (GL_RGBA)
  RgbaHalfUnsized,  // ES 2 + OES_texture_half_float: 4 x uint16 halves
};

enum class Filter { Nearest, Linear };

// RGBA with 8 bits per channel as the API level takes it (sized RGBA8 on
// ES 3, unsized RGBA on ES 2): render targets, packed mosaics, atlases.
TexelFormat rgba8For(ApiLevel api);
// One 8-bit channel: R8 on ES 3, LUMINANCE on ES 2.
TexelFormat r8For(ApiLevel api);

// Bytes a texel occupies on the GPU (what the ledger counts).
std::uint64_t bytesPerTexel(TexelFormat format);
// Bytes of one texel in an upload's `data`.
std::uint64_t uploadBytesPerTexel(TexelFormat format);
// "R8", "RGBA16F", "L8" ... for labels and plans.
const char* texelFormatName(TexelFormat format);

// Float texel components as uploaded for the half-float and 8-bit formats:
// IEEE half floats, and unsigned normalised bytes (clamped to [0, 1], rounded).
std::vector<std::uint16_t> packHalves(const std::vector<float>& values);
std::vector<std::uint8_t> packUnorm8(const std::vector<float>& values);

}  // namespace tessera::gpu
