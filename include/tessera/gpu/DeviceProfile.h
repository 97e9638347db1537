#pragma once
// Device profiles: limits the engine obeys even when the real context offers
// more (DESIGN.md, Device profiles), so that a phone or a WebGL 1 browser can
// be reproduced on any machine. Effective limits = min(profile, queried caps).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "tessera/gpu/DeviceCaps.h"

namespace tessera::gpu {

struct DeviceProfile {
  std::string name;
  std::string note;  // one line: where the numbers come from
  ApiLevel api = ApiLevel::Gles3;
  // Size and unit limits; kUnlimited leaves the context's value.
  static constexpr int kUnlimited = 1 << 30;
  int max2DTextureSize = kUnlimited;
  int max3DTextureSize = 0;         // 0 = no 3D textures (always 0 for gles2)
  int textureUnits = kUnlimited;    // fragment texture image units
  std::uint64_t textureBudget = 0;  // bytes of GPU textures + buffers; 0 = unlimited
  std::uint64_t hostBudget = 0;     // bytes of host memory for volumes; 0 = unlimited
  bool floatRenderTargets = true;   // gles2: false

  // Built-in profiles: the papers' devices (axim-x51v, ipad2,
  // webgl1-desktop-2012, nexus7, shield-k1) and generic ones (gles2, webgl1,
  // gles3, webgl2, native).
  static const std::vector<DeviceProfile>& builtins();
  // A built-in name, or a path to a JSON profile file. InputError listing
  // the built-in names if neither.
  static DeviceProfile find(const std::string& nameOrPath);
  // JSON: {"name", "note", "api": "gles2"|"gles3", "max_2d_texture_size",
  // "max_3d_texture_size", "texture_units", "texture_budget_mb",
  // "host_budget_mb", "float_render_targets"}; InputError naming the file.
  // "name" and "api" are required. Sizes and units are integers or
  // "unlimited" (left out: unlimited; max_3d_texture_size 0 = no 3D textures,
  // the only value gles2 allows and its default). Budgets are MiB, 0 or left
  // out = unlimited. float_render_targets defaults to false for gles2 (and
  // must be) and true for gles3. Unknown keys are errors.
  static DeviceProfile load(const std::filesystem::path& path);
  // `what` names the source in error messages (the file's path).
  static DeviceProfile fromJson(const std::string& text, const std::string& what);
  // Pretty-printed JSON that fromJson() reads back to an equal profile.
  std::string toJson() const;

  bool operator==(const DeviceProfile&) const = default;
};

// "gles2" or "gles3", as in profile files and `tessera profiles`.
const char* apiLevelName(ApiLevel api);

// What the engine may use on this context under this profile.
struct DeviceLimits {
  std::string profile;
  ApiLevel api = ApiLevel::Gles3;
  int max2DTextureSize = 0;
  int max3DTextureSize = 0;  // 0: no 3D textures
  int textureUnits = 0;
  std::uint64_t textureBudget = 0;  // 0 = unlimited
  std::uint64_t hostBudget = 0;     // 0 = unlimited
  bool floatRenderTargets = false;
  // Half floats as a render target: RGBA16F on gles3 (EXT_color_buffer_float
  // or EXT_color_buffer_half_float), RGBA + HALF_FLOAT_OES on gles2
  // (EXT_color_buffer_half_float with OES_texture_half_float, as most WebGL 1
  // browsers and many ES 2 GPUs offer). A profile without float render
  // targets has neither.
  bool halfFloatRenderTargets = false;
  bool norm16Textures = false;  // EXT_texture_norm16 (gles3 only)
  bool halfFloatTextures =
      false;  // RGBA16F textures filterable (gles3, or OES_texture_half_float(_linear))

  // Limits of an unrestricted context (profile "native").
  static DeviceLimits of(const DeviceCaps& caps);
};

// min(profile, caps); the API level is the profile's (a gles2 profile on an
// ES 3 context is an error: create the context with the profile's level).
DeviceLimits effectiveLimits(const DeviceProfile& profile, const DeviceCaps& caps);

}  // namespace tessera::gpu
