#pragma once
#include <cstddef>
#include <string_view>

namespace tessera {

// Voxel value types a Volume can hold.
enum class ScalarType { U8, U16, I16, F32 };

constexpr std::size_t bytesPerVoxel(ScalarType t) {
  switch (t) {
    case ScalarType::U8:
      return 1;
    case ScalarType::U16:
      return 2;
    case ScalarType::I16:
      return 2;
    case ScalarType::F32:
      return 4;
  }
  return 0;
}

constexpr std::string_view scalarTypeName(ScalarType t) {
  switch (t) {
    case ScalarType::U8:
      return "u8";
    case ScalarType::U16:
      return "u16";
    case ScalarType::I16:
      return "i16";
    case ScalarType::F32:
      return "f32";
  }
  return "?";
}

}  // namespace tessera
