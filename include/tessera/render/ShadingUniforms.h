#pragma once
// The define and uniforms of render/shading.glsl, for every technique that
// lights its samples (ray casting, both slicers): one place that turns
// RenderSettings::shading, the camera and the volume's box into what the
// shader needs, so the techniques cannot drift apart.
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/gpu/Program.h"

namespace tessera::render {

// Appends "SHADING 1" when the settings shade (composite mode only: MIP shows
// one classified value and is never lit).
void addShadingDefines(const RenderSettings& settings, std::vector<std::string>& defines);
bool shadingActive(const RenderSettings& settings);
// Throws InputError for coefficients outside their ranges (negative terms,
// shininess outside [1, 512], a zero light direction).
void checkShading(const Shading& shading);

// `program` must be in use and built with the settings' defines.
// `normalisedPerStored`: normalised value per unit of stored value (the value
// window's scale); `extent`, `spacing`: the volume's box and voxel size.
void setShadingUniforms(const gpu::Program& program, const RenderSettings& settings,
                        const Camera& camera, double normalisedPerStored, glm::dvec3 extent,
                        glm::dvec3 spacing);

}  // namespace tessera::render
