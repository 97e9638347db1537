#include "tessera/gpu/DeviceCaps.h"

#include <sstream>

#include "gpu/ErrorQueries.h"
#include "gpu/gl.h"

namespace tessera::gpu {

namespace {
std::string glString(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "";
}
int glInt(GLenum name) {
  GLint v = 0;
  glGetIntegerv(name, &v);
  return v;
}
}  // namespace

DeviceCaps DeviceCaps::query(ApiLevel api) {
  DeviceCaps caps;
  caps.api = api;
  caps.renderer = glString(GL_RENDERER);
  caps.vendor = glString(GL_VENDOR);
  caps.version = glString(GL_VERSION);
  caps.glslVersion = glString(GL_SHADING_LANGUAGE_VERSION);
  caps.max2DTextureSize = glInt(GL_MAX_TEXTURE_SIZE);
  caps.maxTextureUnits = glInt(GL_MAX_TEXTURE_IMAGE_UNITS);
  caps.maxRenderbufferSize = glInt(GL_MAX_RENDERBUFFER_SIZE);
  std::istringstream ext(glString(GL_EXTENSIONS));
  for (std::string e; ext >> e;) caps.extensions.insert(e);
  if (api == ApiLevel::Gles3) caps.max3DTextureSize = glInt(GL_MAX_3D_TEXTURE_SIZE);
  queryError();  // a GLES2 context may flag the ES3-only enums
  return caps;
}

}  // namespace tessera::gpu
