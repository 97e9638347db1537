#include "cli/ClippingOptions.h"

#include <cmath>
#include <sstream>

#include "tessera/core/Error.h"
#include "tessera/render/ClippingUniforms.h"

namespace tessera::app {

namespace {

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, sep)) out.push_back(item);
  return out;
}

// A finite number, or nothing.
bool parseNumber(const std::string& text, double& out) {
  try {
    std::size_t used = 0;
    out = std::stod(text, &used);
    return used == text.size() && std::isfinite(out);
  } catch (const std::exception&) {
    return false;
  }
}

void parseCrop(const std::string& text, Clipping& c) {
  const std::vector<std::string> axes = split(text, ',');
  const char* expected = "': expected x0:x1,y0:y1,z0:z1 in [0,1] (fractions of each axis)";
  if (axes.size() != 3) throw InputError("--crop '" + text + expected);
  for (int a = 0; a < 3; ++a) {
    const std::vector<std::string> range = split(axes[static_cast<std::size_t>(a)], ':');
    double lo = 0.0, hi = 0.0;
    if (range.size() != 2 || !parseNumber(range[0], lo) || !parseNumber(range[1], hi)) {
      throw InputError("--crop '" + text + expected);
    }
    c.cropMin[a] = lo;
    c.cropMax[a] = hi;
  }
}

ClipPlane parsePlane(const std::string& text) {
  const std::vector<std::string> parts = split(text, ',');
  double v[4];
  bool ok = parts.size() == 4;
  for (std::size_t i = 0; ok && i < 4; ++i) ok = parseNumber(parts[i], v[i]);
  if (!ok) {
    throw InputError("--clip '" + text +
                     "': expected NX,NY,NZ,D (normal in the patient frame, D in mm from the "
                     "volume's centre)");
  }
  // Unit normal: D is then a distance in mm.
  const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(len > 0.0)) throw InputError("--clip '" + text + "': the normal must not be zero");
  return {{v[0] / len, v[1] / len, v[2] / len}, v[3]};
}

}  // namespace

void addClippingOptions(CLI::App* cmd, ClippingOptions& o) {
  cmd->add_option("--crop", o.crop,
                  "Crop box x0:x1,y0:y1,z0:z1 as fractions [0,1] of each index axis (so it holds "
                  "when the planner downsamples), e.g. 0:1,0:0.5,0:1 keeps the first half in y");
  cmd->add_option("--clip", o.clip,
                  "Clip plane NX,NY,NZ,D (repeatable, up to 6): cuts away what lies more than D mm "
                  "from the volume's centre along the normal N (patient axes RAS+: x right, y "
                  "anterior, z superior); e.g. 0,1,0,0 removes the anterior half. Samples are "
                  "dropped, never moved");
}

Clipping clippingFrom(const ClippingOptions& o) {
  Clipping c;
  if (!o.crop.empty()) parseCrop(o.crop, c);
  for (const std::string& p : o.clip) c.planes.push_back(parsePlane(p));
  render::checkClipping(c);
  return c;
}

}  // namespace tessera::app
