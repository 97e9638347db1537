#include "tessera/layout/Layout.h"

#include "tessera/core/Error.h"

namespace tessera::layout {

ValueBlocks Layout::valueBlocks(int blockSize) const {
  if (voxels_ == nullptr) {
    throw Error(name() + " layout has no in-core voxels and does not provide its value blocks");
  }
  return ValueBlocks(*voxels_, blockSize, supportVoxels());
}

std::vector<gpu::ShaderPart> Layout::seamParts() const {
  std::vector<gpu::ShaderPart> parts = glslParts();
  parts.push_back(gpu::embeddedShaderPart("layout/gradient.glsl"));
  return parts;
}

int Layout::bindSeam(const gpu::Program& program, int firstUnit) const {
  const int units = bind(program, firstUnit);
  program.set("u_layoutVoxel", glm::vec3(1.0f) / glm::vec3(volumeDims()));
  return units;
}

}  // namespace tessera::layout
