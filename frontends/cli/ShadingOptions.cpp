#include "cli/ShadingOptions.h"

#include <cmath>
#include <sstream>
#include <vector>

#include "cli/Options.h"
#include "tessera/core/Error.h"
#include "tessera/render/ShadingUniforms.h"

namespace tessera::app {

namespace {

glm::dvec3 parseLightDirection(const std::string& text) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double d = 0.0;
    try {
      d = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(d)) {
      throw InputError("--light '" + text + "': expected headlight or X,Y,Z (e.g. 0,1,1)");
    }
    v.push_back(d);
  }
  if (v.size() != 3) {
    throw InputError("--light '" + text + "': expected headlight or three numbers X,Y,Z");
  }
  return {v[0], v[1], v[2]};
}

}  // namespace

void addShadingOptions(CLI::App* cmd, ShadingOptions& o) {
  cmd->add_flag("--shade", o.shade,
                "Blinn-Phong shading from the gradient of the reconstructed field; composite "
                "mode only");
  cmd->add_option("--gradient", o.gradient,
                  "With --shade (raycast): 'precomputed' (per-voxel central differences in an "
                  "RGBA8 3D texture: 1 fetch per lit sample, 4 bytes per voxel), 'on-the-fly' "
                  "(central differences through the layout: 6 fetches, no memory) or 'auto' "
                  "(precomputed where the device has 3D textures and the budget holds it)")
      ->check(CLI::IsMember({"auto", "on-the-fly", "precomputed"}))
      ->capture_default_str();
  addDefaultedOption(cmd, "--light", o.light,
                     "With --shade: 'headlight' (light from the viewer) or a fixed direction "
                     "towards the light X,Y,Z in the patient frame (RAS+: x right, y anterior, "
                     "z superior), e.g. 0,1,1 from the front and above");
  cmd->add_option("--gradient-opacity", o.gradientOpacity,
                  "Gradient-magnitude opacity modulation, LOW,HIGH (or 'on' for " +
                      std::to_string(Shading{}.gradientLow).substr(0, 4) + "," +
                      std::to_string(Shading{}.gradientHigh).substr(0, 4) +
                      "): a sample's opacity is scaled by clamp((|gradient| - LOW) / (HIGH - "
                      "LOW), 0, 1), |gradient| in normalised value per voxel, so homogeneous "
                      "regions fade and boundaries stay; with or without --shade; composite "
                      "mode only");
  addDefaultedOption(cmd, "--ambient", o.coefficients.ambient, "With --shade: ambient term");
  addDefaultedOption(cmd, "--diffuse", o.coefficients.diffuse, "With --shade: diffuse term");
  addDefaultedOption(cmd, "--specular", o.coefficients.specular,
                     "With --shade: specular term (white highlights)");
  addDefaultedOption(cmd, "--shininess", o.coefficients.shininess,
                     "With --shade: specular exponent, 1..512");
}

Shading shadingFrom(const ShadingOptions& o) {
  Shading s = o.coefficients;
  s.enabled = o.shade;
  if (!o.gradientOpacity.empty() && o.gradientOpacity != "off") {
    s.gradientOpacity = true;
    if (o.gradientOpacity != "on") {
      double low = 0.0, high = 0.0;
      char comma = 0, extra = 0;
      std::istringstream in(o.gradientOpacity);
      if (!(in >> low >> comma >> high) || comma != ',' || (in >> extra)) {
        throw InputError("--gradient-opacity '" + o.gradientOpacity +
                         "': expected on, off or LOW,HIGH (e.g. 0.01,0.06)");
      }
      s.gradientLow = low;
      s.gradientHigh = high;
    }
  }
  s.headlight = o.light == "headlight";
  if (!s.headlight) s.lightDirection = parseLightDirection(o.light);
  render::checkShading(s);
  return s;
}

}  // namespace tessera::app
