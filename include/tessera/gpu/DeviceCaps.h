#pragma once
#include <set>
#include <string>

namespace tessera::gpu {

// OpenGL ES API level of a context (Filament-style feature level as data).
enum class ApiLevel { Gles2, Gles3 };

// What the current context reports. Queried once per context.
struct DeviceCaps {
  ApiLevel api = ApiLevel::Gles3;
  std::string renderer;
  std::string vendor;
  std::string version;
  std::string glslVersion;
  int max2DTextureSize = 0;
  int max3DTextureSize = 0;  // 0 when 3D textures are unavailable
  int maxTextureUnits = 0;   // fragment-shader texture image units
  int maxRenderbufferSize = 0;
  std::set<std::string> extensions;

  bool has(const std::string& extension) const { return extensions.count(extension) != 0; }
  // Queries the current context.
  static DeviceCaps query(ApiLevel api);
};

}  // namespace tessera::gpu
