#pragma once
// The define and uniforms of render/clipping.glsl for every technique (ray
// casting, both slicers), from RenderSettings::clipping and the camera's
// patient -> model rotation.
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/gpu/Program.h"

namespace tessera::render {

// Appends "CLIPPING 1" when the settings clip or crop.
void addClippingDefines(const RenderSettings& settings, std::vector<std::string>& defines);
// InputError for more than kMaxClipPlanes planes, a zero or non-finite
// normal, or a crop box outside [0,1] or empty.
void checkClipping(const Clipping& clipping);
// `program` must be in use and built with the settings' defines.
void setClippingUniforms(const gpu::Program& program, const RenderSettings& settings,
                         const Camera& camera, glm::dvec3 extent);

}  // namespace tessera::render
