#include "tessera/render/LabelTable.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"

namespace tessera::render {

namespace {

bool isInteger(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

void checkValue(long value, const std::string& where) {
  if (value < 0 || value > 255) {
    throw InputError(where + ": label value " + std::to_string(value) +
                     " is outside 0..255 (8-bit label volumes)");
  }
}

glm::dvec3 hsvToRgb(double h, double s, double v) {
  const double c = v * s, hp = h * 6.0, x = c * (1.0 - std::abs(std::fmod(hp, 2.0) - 1.0));
  glm::dvec3 rgb = hp < 1   ? glm::dvec3(c, x, 0)
                   : hp < 2 ? glm::dvec3(x, c, 0)
                   : hp < 3 ? glm::dvec3(0, c, x)
                   : hp < 4 ? glm::dvec3(0, x, c)
                   : hp < 5 ? glm::dvec3(x, 0, c)
                            : glm::dvec3(c, 0, x);
  return rgb + (v - c);
}

// A line of a label text file, split on white space; a quoted name is one token.
std::vector<std::string> tokens(const std::string& line) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i >= line.size()) break;
    if (line[i] == '"') {
      const std::size_t end = line.find('"', i + 1);
      out.push_back(line.substr(i + 1, end == std::string::npos ? std::string::npos : end - i - 1));
      i = end == std::string::npos ? line.size() : end + 1;
    } else {
      std::size_t j = i;
      while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
      out.push_back(line.substr(i, j - i));
      i = j;
    }
  }
  return out;
}

double channel(const std::string& s, const std::string& where) {
  if (!isInteger(s) || std::stol(s) > 255) {
    throw InputError(where + ": colour channel '" + s + "' is not an integer 0..255");
  }
  return std::stol(s) / 255.0;
}

}  // namespace

glm::dvec3 LabelTable::paletteColor(int value) {
  // Golden-angle hues, two saturation/value levels: neighbouring labels differ.
  const double hue = std::fmod(value * 0.618033988749895, 1.0);
  return hsvToRgb(hue, value % 2 ? 0.75 : 0.55, value % 3 ? 0.95 : 0.8);
}

void prepareLabelVolume(Volume& volume) {
  const ValueRange r = volume.valueRange();
  if (r.min < 0.0 || r.max > 255.0) {
    throw InputError("label volume values span " + std::to_string(r.min) + ".." +
                     std::to_string(r.max) + "; labels must be integers in 0..255");
  }
  const std::size_t n = static_cast<std::size_t>(volume.voxelCount());
  for (std::size_t i = 0; i < n; i += 1) {
    const double v = volume.finiteValueAtIndex(i);
    if (v != std::floor(v)) {
      throw InputError("label volume holds the non-integer value " + std::to_string(v) +
                       "; labels must be integers in 0..255");
    }
  }
  volume.setWindow({0.0, 255.0});
}

void applyLabelSettings(RenderSettings& settings) {
  settings.nearest = true;
}

LabelTable LabelTable::defaultFor(const Volume& volume) {
  Volume copy = volume;  // checks only
  prepareLabelVolume(copy);
  std::set<int> present;
  const std::size_t n = static_cast<std::size_t>(volume.voxelCount());
  for (std::size_t i = 0; i < n; ++i)
    present.insert(static_cast<int>(volume.finiteValueAtIndex(i)));
  LabelTable t;
  for (int v : present) {
    if (v == 0) continue;
    t.labels[v] = {"label " + std::to_string(v), paletteColor(v), 1.0, true};
  }
  return t;
}

LabelTable LabelTable::fromJson(const std::string& text, const std::string& what) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(what + ": not JSON (" + e.what() + ")");
  }
  if (!j.is_object() || !j.contains("labels") || !j["labels"].is_array()) {
    throw InputError(what + ": expected {\"labels\": [{\"value\": N, \"color\": [r,g,b]}, ...]}");
  }
  LabelTable t;
  for (std::size_t i = 0; i < j["labels"].size(); ++i) {
    const nlohmann::json& e = j["labels"][i];
    const std::string where = what + ": labels[" + std::to_string(i) + "]";
    if (!e.is_object() || !e.contains("value") || !e["value"].is_number_integer()) {
      throw InputError(where + ": needs an integer \"value\"");
    }
    const long value = e["value"].get<long>();
    checkValue(value, where);
    Label l;
    l.name = e.value("name", "label " + std::to_string(value));
    l.color = paletteColor(static_cast<int>(value));
    if (e.contains("color")) {
      const nlohmann::json& c = e["color"];
      if (!c.is_array() || c.size() != 3 || !c[0].is_number() || !c[1].is_number() ||
          !c[2].is_number()) {
        throw InputError(where + ": \"color\" must be [r, g, b] in 0..1");
      }
      l.color = {c[0].get<double>(), c[1].get<double>(), c[2].get<double>()};
      for (int k = 0; k < 3; ++k) {
        if (!(l.color[k] >= 0.0 && l.color[k] <= 1.0)) {
          throw InputError(where + ": \"color\" must be [r, g, b] in 0..1");
        }
      }
    }
    if (e.contains("opacity")) {
      if (!e["opacity"].is_number() || !(e["opacity"].get<double>() >= 0.0) ||
          e["opacity"].get<double>() > 1.0) {
        throw InputError(where + ": \"opacity\" must be a number in 0..1");
      }
      l.opacity = e["opacity"].get<double>();
    }
    if (e.contains("visible")) {
      if (!e["visible"].is_boolean()) throw InputError(where + ": \"visible\" must be true/false");
      l.visible = e["visible"].get<bool>();
    }
    t.labels[static_cast<int>(value)] = l;
  }
  return t;
}

LabelTable LabelTable::fromText(const std::string& text, const std::string& what) {
  LabelTable t;
  std::istringstream in(text);
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    const std::string where = what + ":" + std::to_string(lineNo);
    const std::vector<std::string> tok = tokens(line);
    if (tok.empty() || tok[0][0] == '#') continue;
    if (!isInteger(tok[0]) || tok[0].size() > 6) {
      throw InputError(where + ": expected a label value first, got '" + tok[0] + "'");
    }
    const long value = std::stol(tok[0]);
    checkValue(value, where);
    Label l;
    l.color = paletteColor(static_cast<int>(value));
    if (tok.size() >= 8 && isInteger(tok[1])) {
      // ITK-SNAP: IDX R G B A(0..1) VIS MSH "LABEL"
      l.color = {channel(tok[1], where), channel(tok[2], where), channel(tok[3], where)};
      std::istringstream a(tok[4]);
      double alpha = -1.0;
      a >> alpha;
      if (!a || !(alpha >= 0.0 && alpha <= 1.0)) {
        throw InputError(where + ": opacity '" + tok[4] + "' is not a number in 0..1");
      }
      l.opacity = alpha;
      if (tok[5] != "0" && tok[5] != "1") throw InputError(where + ": visibility must be 0 or 1");
      l.visible = tok[5] == "1";
      l.name = tok[7];
    } else if (tok.size() >= 5 && !isInteger(tok[1]) && isInteger(tok[2])) {
      // FreeSurfer colour LUT: IDX NAME R G B A
      l.name = tok[1];
      l.color = {channel(tok[2], where), channel(tok[3], where), channel(tok[4], where)};
    } else if (tok.size() >= 2 && !isInteger(tok[1])) {
      // mricron's atlas text: IDX NAME [CODE]
      l.name = tok[1];
    } else {
      throw InputError(where +
                       ": expected ITK-SNAP (IDX R G B A VIS MSH \"NAME\"), FreeSurfer (IDX NAME "
                       "R G B A) or IDX NAME");
    }
    if (value == 0) continue;  // the background is never drawn
    t.labels[static_cast<int>(value)] = l;
  }
  if (t.labels.empty()) throw InputError(what + ": no labels (besides 0) in the file");
  return t;
}

LabelTable LabelTable::load(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError("cannot open label table " + path.string());
  std::ostringstream s;
  s << f.rdbuf();
  const std::string text = s.str();
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (path.extension() == ".json" || (first != std::string::npos && text[first] == '{')) {
    return fromJson(text, path.string());
  }
  return fromText(text, path.string());
}

TransferFunction LabelTable::toTransferFunction() const {
  TransferFunction tf;
  tf.name = "labels";
  for (int v = 0; v < 256; ++v) {
    const auto it = labels.find(v);
    const bool shown = it != labels.end() && it->second.visible && v != 0;
    const double x = v / 255.0;
    tf.addColor(x, shown ? it->second.color : glm::dvec3(0.0));
    tf.addOpacity(x, shown ? it->second.opacity : 0.0);
  }
  return tf;
}

}  // namespace tessera::render
