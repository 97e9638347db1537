#include <algorithm>

#include "tessera/core/Error.h"
#include "tessera/gpu/DeviceProfile.h"

namespace tessera::gpu {

DeviceLimits DeviceLimits::of(const DeviceCaps& caps) {
  DeviceLimits l;
  l.profile = "native";
  l.api = caps.api;
  l.max2DTextureSize = caps.max2DTextureSize;
  l.max3DTextureSize = caps.api == ApiLevel::Gles3 ? caps.max3DTextureSize : 0;
  l.textureUnits = caps.maxTextureUnits;
  if (caps.api == ApiLevel::Gles3) {
    l.floatRenderTargets = caps.has("GL_EXT_color_buffer_float");
    l.halfFloatRenderTargets = l.floatRenderTargets || caps.has("GL_EXT_color_buffer_half_float");
    l.norm16Textures = caps.has("GL_EXT_texture_norm16");
    l.halfFloatTextures = true;  // RGBA16F is filterable in ES 3.0
  } else {
    l.floatRenderTargets = false;
    l.halfFloatRenderTargets =
        caps.has("GL_EXT_color_buffer_half_float") && caps.has("GL_OES_texture_half_float");
    l.norm16Textures = false;
    l.halfFloatTextures =
        caps.has("GL_OES_texture_half_float") && caps.has("GL_OES_texture_half_float_linear");
  }
  return l;
}

DeviceLimits effectiveLimits(const DeviceProfile& profile, const DeviceCaps& caps) {
  if (profile.api == ApiLevel::Gles2 && caps.api != ApiLevel::Gles2) {
    throw GpuError("profile " + profile.name +
                   " is gles2 but the context is ES 3: create the context at the profile's level");
  }
  if (profile.api == ApiLevel::Gles3 && caps.api != ApiLevel::Gles3) {
    throw GpuError("profile " + profile.name + " needs an OpenGL ES 3.0 context");
  }
  DeviceLimits l = DeviceLimits::of(caps);
  l.profile = profile.name;
  l.max2DTextureSize = std::min(profile.max2DTextureSize, caps.max2DTextureSize);
  l.max3DTextureSize =
      profile.api == ApiLevel::Gles3 ? std::min(profile.max3DTextureSize, l.max3DTextureSize) : 0;
  l.textureUnits = std::min(profile.textureUnits, caps.maxTextureUnits);
  l.textureBudget = profile.textureBudget;
  l.hostBudget = profile.hostBudget;
  l.floatRenderTargets = l.floatRenderTargets && profile.floatRenderTargets;
  l.halfFloatRenderTargets = l.halfFloatRenderTargets && profile.floatRenderTargets;
  return l;
}

}  // namespace tessera::gpu
