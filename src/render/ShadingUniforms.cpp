#include "tessera/render/ShadingUniforms.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include "tessera/core/Error.h"

namespace tessera::render {

bool shadingActive(const RenderSettings& settings) {
  return litSamples(settings);
}

void addShadingDefines(const RenderSettings& settings, std::vector<std::string>& defines) {
  if (!shadingActive(settings)) return;
  defines.push_back("SHADING 1");  // the gradient
  if (settings.shading.enabled) defines.push_back("LIGHTING 1");
  if (settings.shading.gradientOpacity) defines.push_back("GRADIENT_OPACITY 1");
}

void checkShading(const Shading& shading) {
  for (const double k : {shading.ambient, shading.diffuse, shading.specular}) {
    if (!(k >= 0.0) || !std::isfinite(k)) {
      throw InputError("shading: ambient, diffuse and specular must be finite and >= 0, got " +
                       std::to_string(k));
    }
  }
  if (!(shading.shininess >= 1.0 && shading.shininess <= 512.0)) {
    throw InputError("shading: shininess must be 1..512, got " + std::to_string(shading.shininess));
  }
  if (shading.gradientOpacity &&
      !(shading.gradientLow >= 0.0 && shading.gradientHigh > shading.gradientLow &&
        std::isfinite(shading.gradientHigh))) {
    throw InputError(
        "gradient opacity: expected 0 <= low < high (gradient magnitude in "
        "normalised value per voxel), got " +
        std::to_string(shading.gradientLow) + ", " + std::to_string(shading.gradientHigh));
  }
  if (!shading.headlight && !(glm::length(shading.lightDirection) > 1e-9)) {
    throw InputError("shading: the light direction must not be zero");
  }
}

void setShadingUniforms(const gpu::Program& program, const RenderSettings& settings,
                        const Camera& camera, double normalisedPerStored, glm::dvec3 extent,
                        glm::dvec3 spacing) {
  if (!shadingActive(settings)) return;
  const Shading& s = settings.shading;
  checkShading(s);
  const ShadingLight light = shadingLight(s, camera.basis()[2], camera.modelFromWorld);
  // d(stored)/dp -> d(normalised)/d(model) * (smallest voxel): p = x / extent + 0.5.
  const double minSpacing = std::min({spacing.x, spacing.y, spacing.z});
  program.set("u_shadeGradientScale", glm::vec3(normalisedPerStored * minSpacing / extent));
  program.set("u_shadeLight", glm::vec3(light.l));
  program.set("u_shadeHalf", glm::vec3(light.h));
  program.set("u_shadeCoefficients",
              glm::vec4(static_cast<float>(s.ambient), static_cast<float>(s.diffuse),
                        static_cast<float>(s.specular), static_cast<float>(s.shininess)));
  if (s.gradientOpacity) {
    program.set("u_gradientOpacity",
                glm::vec2(static_cast<float>(s.gradientLow), static_cast<float>(s.gradientHigh)));
  }
}

}  // namespace tessera::render
