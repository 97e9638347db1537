#include "tessera/io/ZarrStore.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <future>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {

namespace {

using nlohmann::json;

// Metadata documents are small; a multi-megabyte .zattrs is not one.
constexpr std::uint64_t kMaxMetadataBytes = 16ull << 20;

enum Role { kX = 0, kY = 1, kZ = 2, kT = 3, kC = 4 };

std::string text(const std::vector<std::byte>& b) {
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

json parseJson(const std::string& body, const std::string& where) {
  try {
    return json::parse(body);
  } catch (const json::exception& e) {
    throw InputError(where + ": not valid JSON (" + e.what() + ")");
  }
}

double unitInMm(const std::string& unit) {
  if (unit == "millimeter") return 1.0;
  if (unit == "micrometer") return 1e-3;
  if (unit == "nanometer") return 1e-6;
  if (unit == "centimeter") return 10.0;
  if (unit == "meter") return 1000.0;
  if (unit == "angstrom") return 1e-7;
  if (unit == "inch") return 25.4;
  return 0.0;
}

// The numbers of a "scale" or "translation" transform, one per axis.
std::vector<double> transformValues(const json& t, const char* key, std::size_t rank,
                                    const std::string& where) {
  if (!t.contains(key) || !t[key].is_array() || t[key].size() != rank) {
    throw InputError(where + ": coordinateTransformations " + t.dump() + " needs \"" + key +
                     "\" with " + std::to_string(rank) + " numbers (one per axis)");
  }
  std::vector<double> v;
  for (const json& x : t[key]) {
    if (!x.is_number() || !std::isfinite(x.get<double>())) {
      throw InputError(where + ": " + key + " " + t[key].dump() + " holds a non-finite value");
    }
    v.push_back(x.get<double>());
  }
  return v;
}

// Applies a coordinateTransformations list to (scale, translation).
void applyTransforms(const json& list, std::size_t rank, const std::string& where,
                     std::vector<double>& scale, std::vector<double>& translation) {
  if (list.is_null()) return;
  if (!list.is_array()) throw InputError(where + ": coordinateTransformations is not a list");
  for (const json& t : list) {
    const std::string type = t.is_object() ? t.value("type", std::string()) : std::string();
    if (type == "scale") {
      const std::vector<double> s = transformValues(t, "scale", rank, where);
      for (std::size_t a = 0; a < rank; ++a) {
        scale[a] *= s[a];
        translation[a] *= s[a];
      }
    } else if (type == "translation") {
      const std::vector<double> d = transformValues(t, "translation", rank, where);
      for (std::size_t a = 0; a < rank; ++a) translation[a] += d[a];
    } else if (type != "identity") {
      throw InputError(where + ": coordinateTransformation " + t.dump() +
                       " is not scale, translation or identity");
    }
  }
}

// NGFF 0.4 and later ("Multiscales metadata"): a dataset's
// coordinateTransformations, and the multiscales' own when present, are
// exactly one "scale", then at most one "translation". Stores older than
// 0.4 had none, so they are held to it only from 0.4 on.
bool ngffHasTransforms(const std::string& version) {
  return !version.empty() && version != "?" && std::strtod(version.c_str(), nullptr) >= 0.4 - 1e-9;
}

void checkTransformOrder(const json& list, bool required, const std::string& what,
                         const std::string& version, const std::string& where) {
  if (list.is_null() && !required) return;
  const auto typeIs = [&list](std::size_t i, const char* type) {
    const json& t = list[i];
    if (!t.is_object()) return false;
    const auto it = t.find("type");
    return it != t.end() && it->is_string() && it->get<std::string>() == type;
  };
  const bool ok = list.is_array() && (list.size() == 1 || list.size() == 2) && typeIs(0, "scale") &&
                  (list.size() == 1 || typeIs(1, "translation"));
  if (ok) return;
  std::string got = list.is_null() ? std::string("none") : list.dump();
  if (got.size() > 160) got = got.substr(0, 157) + "...";
  throw InputError(where + ": " + what + " coordinateTransformations must be one \"scale\", " +
                   "then at most one \"translation\" (OME-NGFF " + version + "); got " + got);
}

template <class T>
T roundedFill(double v) {
  if (std::isnan(v)) return T(0);
  const double lo = double(std::numeric_limits<T>::min());
  const double hi = double(std::numeric_limits<T>::max());
  return static_cast<T>(std::clamp(std::nearbyint(v), lo, hi));
}

// One element of a decoded chunk as double (any supported dtype, either
// byte order).
double elementValue(const std::byte* p, const ZarrArrayMeta& m) {
  std::byte b[8];
  std::memcpy(b, p, static_cast<std::size_t>(m.itemSize));
  if (m.bigEndian != (std::endian::native == std::endian::big)) {
    std::reverse(b, b + m.itemSize);
  }
  auto as = [&b]<class T>(T) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return static_cast<double>(v);
  };
  switch (m.kind) {
    case 'b':
      return b[0] != std::byte{0} ? 1.0 : 0.0;
    case 'u':
      return m.itemSize == 1   ? as(std::uint8_t{})
             : m.itemSize == 2 ? as(std::uint16_t{})
             : m.itemSize == 4 ? as(std::uint32_t{})
                               : as(std::uint64_t{});
    case 'i':
      return m.itemSize == 1   ? as(std::int8_t{})
             : m.itemSize == 2 ? as(std::int16_t{})
             : m.itemSize == 4 ? as(std::int32_t{})
                               : as(std::int64_t{});
    default:
      return m.itemSize == 4 ? as(float{}) : as(double{});
  }
}

}  // namespace

ZarrStore::ZarrStore(std::shared_ptr<const ZarrStorage> storage, ZarrSelection selection)
    : storage_(std::move(storage)),
      selection_(selection),
      chunks_(std::make_shared<ZarrChunkCache>(0)) {
  const auto attrs = storage_->get(".zattrs", kMaxMetadataBytes);
  // A metadata field of the wrong JSON type is a bad store, not a crash.
  try {
    bool multiscales = false;
    if (attrs) {
      attrsWhere_ = storage_->locate(".zattrs");
      attrsText_ = ngffText_ = text(*attrs);
      multiscales = parseJson(attrsText_, attrsWhere_).contains("multiscales");
    } else if (const auto root = storage_->get("zarr.json", kMaxMetadataBytes)) {
      format_ = 3;
      multiscales = readV3Root(text(*root));
    }
    if (multiscales) {
      readMultiscales();
    } else {
      readLoneArray();
    }
    checkSelection();
    makeShape();
  } catch (const json::exception& e) {
    throw InputError(storage_->describe() + ": metadata field of the wrong type or value (" +
                     e.what() + ")");
  }
}

bool ZarrStore::readV3Root(const std::string& body) {
  attrsWhere_ = storage_->locate("zarr.json");
  const json doc = parseJson(body, attrsWhere_);
  if (!doc.is_object() || !doc.contains("zarr_format") || doc["zarr_format"] != 3) {
    throw InputError(
        attrsWhere_ + ": zarr_format is " +
        (doc.is_object() && doc.contains("zarr_format") ? doc["zarr_format"].dump() : "missing") +
        ", expected 3 (Zarr v3)");
  }
  const std::string node = doc.value("node_type", std::string());
  if (node == "array") return false;  // a lone array at the root
  if (node != "group") {
    throw InputError(attrsWhere_ + ": node_type is " +
                     (doc.contains("node_type") ? doc["node_type"].dump() : "missing") +
                     ", expected \"group\" or \"array\"");
  }
  const json attributes = doc.contains("attributes") ? doc["attributes"] : json::object();
  if (!attributes.is_object()) throw InputError(attrsWhere_ + ": attributes is not an object");
  attrsText_ = attributes.dump();
  // NGFF 0.5: everything under "ome" (its version there); an older layout
  // on v3 keeps multiscales at the top of the attributes.
  if (attributes.contains("ome") && attributes["ome"].is_object()) {
    const json& ome = attributes["ome"];
    ngffText_ = ome.dump();
    version_ = ome.contains("version") && ome["version"].is_string()
                   ? ome["version"].get<std::string>()
                   : "?";
    if (ome.contains("multiscales")) return true;
  } else {
    ngffText_ = attrsText_;
    if (attributes.contains("multiscales")) return true;
  }
  throw InputError(attrsWhere_ + ": a Zarr v3 group without OME-NGFF multiscales (no " +
                   "attributes.ome.multiscales)");
}

ZarrArrayMeta ZarrStore::readArrayMeta(const std::string& path) const {
  const std::string key =
      (path.empty() ? "" : path + "/") + (format_ == 3 ? "zarr.json" : ".zarray");
  const auto meta = storage_->get(key, kMaxMetadataBytes);
  if (!meta) {
    throw InputError(storage_->locate(key) + ": missing" +
                     (path.empty() ? std::string() : " (dataset \"" + path + "\")"));
  }
  return format_ == 3 ? parseZarrJsonArray(text(*meta), storage_->locate(key))
                      : parseZarray(text(*meta), storage_->locate(key));
}

const ZarrLevel& ZarrStore::level(int l) const {
  if (l < 0 || l >= levelCount()) {
    throw InputError(storage_->describe() + ": level " + std::to_string(l) + " does not exist (" +
                     std::to_string(levelCount()) + " levels)");
  }
  return levels_[static_cast<std::size_t>(l)];
}

void ZarrStore::readLoneArray() {
  const char* metaKey = format_ == 3 ? "zarr.json" : ".zarray";
  if (format_ == 2 && !storage_->get(".zarray", kMaxMetadataBytes)) {
    throw InputError(storage_->describe() +
                     ": not an OME-Zarr store (no .zattrs with \"multiscales\", no .zarray and "
                     "no zarr.json)");
  }
  version_ = format_ == 3 ? "plain Zarr v3 array" : "plain Zarr array";
  notes_.push_back("no OME-NGFF multiscales: one level, spacing 1 mm, origin 0");
  const ZarrArrayMeta m = readArrayMeta("");
  const int rank = m.rank();
  if (rank < 3) {
    throw InputError(storage_->locate(metaKey) + ": " + std::to_string(rank) +
                     " axes; a volume needs 3 (z, y, x) to 5 (t, c, z, y, x)");
  }
  axis_[kX] = rank - 1;
  axis_[kY] = rank - 2;
  axis_[kZ] = rank - 3;
  if (rank == 5) axis_[kT] = 0;
  if (rank >= 4) axis_[kC] = rank - 4;
  levels_.push_back({});
  levels_.back().array = m;
  addLevel("", glm::dvec3(1.0), glm::dvec3(0.0));
}

void ZarrStore::readMultiscales() {
  const std::string where = attrsWhere_;
  const json attrs = parseJson(attrsText_, where);
  const json ngff = parseJson(ngffText_, where);
  const json& all = ngff["multiscales"];
  if (!all.is_array() || all.empty() || !all[0].is_object()) {
    throw InputError(where + ": \"multiscales\" must be a non-empty list of objects");
  }
  if (all.size() > 1) notes_.push_back("the store holds several multiscales; reading the first");
  const json& ms = all[0];
  if (ms.contains("version") && ms["version"].is_string()) {
    version_ = ms["version"].get<std::string>();
  } else if (version_.empty()) {
    version_ = "?";
  }
  name_ = ms.contains("name") && ms["name"].is_string() ? ms["name"].get<std::string>() : "";
  reduction_ = ms.contains("type") && ms["type"].is_string() ? ms["type"].get<std::string>() : "";
  if (!ms.contains("datasets") || !ms["datasets"].is_array() || ms["datasets"].empty()) {
    throw InputError(where + ": multiscales[0] has no \"datasets\"");
  }
  // Axes: 0.4 objects {name, type, unit}, 0.3 names, or (0.1/0.2) none.
  std::vector<std::string> names;
  std::string unit;
  if (ms.contains("axes")) {
    if (!ms["axes"].is_array()) throw InputError(where + ": \"axes\" is not a list");
    for (const json& a : ms["axes"]) {
      if (a.is_string()) {
        names.push_back(a.get<std::string>());
      } else if (a.is_object() && a.contains("name") && a["name"].is_string()) {
        names.push_back(a["name"].get<std::string>());
        const std::string type = a.value("type", std::string());
        const std::string& name = names.back();
        if ((name == "x" || name == "y" || name == "z") && a.contains("type") && type != "space" &&
            type != "time" && type != "channel") {
          throw InputError(where + ": axis \"" + name + "\" has type " + a["type"].dump() +
                           "; x, y and z are \"space\" axes");
        }
        if (type == "time") names.back() = "t";
        if (type == "channel") names.back() = "c";
        if (a.contains("unit") && a["unit"].is_string() && type == "space") {
          unit = a["unit"].get<std::string>();
        }
      } else {
        throw InputError(where + ": axis " + a.dump() + " has no name");
      }
    }
  }
  if (names.empty()) names = {"t", "c", "z", "y", "x"};
  if (names.size() < 3 || names.size() > 5) {
    throw InputError(where + ": " + std::to_string(names.size()) +
                     " axes; a volume needs 3 (z, y, x) to 5 (t, c, z, y, x)");
  }
  const char* roleNames[] = {"x", "y", "z", "t", "c"};
  for (std::size_t a = 0; a < names.size(); ++a) {
    int role = -1;
    for (int r = 0; r < 5; ++r) {
      if (names[a] == roleNames[r]) role = r;
    }
    if (role < 0 || axis_[role] >= 0) {
      throw InputError(where + ": axis \"" + names[a] +
                       "\" is not one of t, c, z, y, x (each at most once)");
    }
    axis_[role] = static_cast<int>(a);
  }
  if (axis_[kX] < 0 || axis_[kY] < 0 || axis_[kZ] < 0) {
    throw InputError(where + ": axes need x, y and z (a 2D image is not a volume)");
  }
  unitToMm_ = unit.empty() ? 1.0 : unitInMm(unit);
  if (unit.empty()) notes_.push_back("the space axes have no unit: taken as millimetres");
  if (unitToMm_ == 0.0) {
    notes_.push_back("unknown unit \"" + unit + "\": taken as millimetres");
    unitToMm_ = 1.0;
  }
  const std::size_t rank = names.size();
  const bool transformsRequired = ngffHasTransforms(version_);
  if (transformsRequired) {
    checkTransformOrder(
        ms.contains("coordinateTransformations") ? ms["coordinateTransformations"] : json(), false,
        "multiscales[0]", version_, where);
  }
  for (const json& d : ms["datasets"]) {
    if (!d.is_object() || !d.contains("path") || !d["path"].is_string()) {
      throw InputError(where + ": dataset " + d.dump() + " has no \"path\"");
    }
    const std::string path = d["path"].get<std::string>();
    if (transformsRequired) {
      checkTransformOrder(
          d.contains("coordinateTransformations") ? d["coordinateTransformations"] : json(), true,
          "dataset \"" + path + "\"", version_, where);
    }
    std::vector<double> scale(rank, 1.0), translation(rank, 0.0);
    applyTransforms(
        d.contains("coordinateTransformations") ? d["coordinateTransformations"] : json(), rank,
        where, scale, translation);
    applyTransforms(
        ms.contains("coordinateTransformations") ? ms["coordinateTransformations"] : json(), rank,
        where, scale, translation);
    const std::string key = path + (format_ == 3 ? "/zarr.json" : "/.zarray");
    levels_.push_back({});
    levels_.back().array = readArrayMeta(path);
    if (levels_.back().array.rank() != static_cast<int>(rank)) {
      throw InputError(storage_->locate(key) + ": " + std::to_string(levels_.back().array.rank()) +
                       " axes, multiscales has " + std::to_string(rank));
    }
    const glm::dvec3 s(scale[std::size_t(axis_[kX])], scale[std::size_t(axis_[kY])],
                       scale[std::size_t(axis_[kZ])]);
    const glm::dvec3 t(translation[std::size_t(axis_[kX])], translation[std::size_t(axis_[kY])],
                       translation[std::size_t(axis_[kZ])]);
    addLevel(path, s * unitToMm_, t * unitToMm_);
  }
  if (attrs.contains("tessera") && attrs["tessera"].is_object() &&
      attrs["tessera"].contains("direction")) {
    const json& dir = attrs["tessera"]["direction"];
    glm::dmat3 m(1.0);
    if (!dir.is_array() || dir.size() != 3) {
      throw InputError(where + ": tessera.direction must be 3 columns of 3 numbers");
    }
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) {
        const json& x = dir[std::size_t(c)];
        if (!x.is_array() || x.size() != 3 || !x[std::size_t(r)].is_number()) {
          throw InputError(where + ": tessera.direction must be 3 columns of 3 numbers");
        }
        m[c][r] = x[std::size_t(r)].get<double>();
      }
    }
    direction_ = m;
    // Stores written since translations were fixed give them in the
    // array's own axes (what NGFF means): a level's world origin is level
    // 0's plus the direction applied to its half-voxel shift. Older
    // Tessera stores wrote the world shift itself.
    if (attrs["tessera"].value("translations", std::string()) == "array axes") {
      const glm::dvec3 t0 = levels_.front().origin;
      for (ZarrLevel& lv : levels_) lv.origin = t0 + direction_ * (lv.origin - t0);
    }
  }
  readChannels();
}

void ZarrStore::readChannels() {
  const json ngff = parseJson(ngffText_, attrsWhere_);
  if (!ngff.contains("omero") || !ngff["omero"].is_object()) return;
  const json& ch = ngff["omero"].contains("channels") ? ngff["omero"]["channels"] : json();
  if (!ch.is_array()) return;
  for (const json& c : ch) {
    ZarrChannel out;
    if (!c.is_object()) {
      channels_.push_back(out);
      continue;
    }
    if (c.contains("label") && c["label"].is_string()) out.label = c["label"].get<std::string>();
    if (c.contains("active") && c["active"].is_boolean()) out.active = c["active"].get<bool>();
    const std::string which = "omero channel " + std::to_string(channels_.size());
    if (c.contains("color") && !c["color"].is_string()) {
      notes_.push_back(which + " colour " + c["color"].dump() +
                       " is not an \"RRGGBB\" string: white");
    }
    if (c.contains("color") && c["color"].is_string()) {
      const std::string hex = c["color"].get<std::string>();
      if (hex.size() == 6 && hex.find_first_not_of("0123456789abcdefABCDEF") == std::string::npos) {
        const unsigned long rgb = std::stoul(hex, nullptr, 16);
        out.color =
            glm::vec3(float((rgb >> 16) & 0xff), float((rgb >> 8) & 0xff), float(rgb & 0xff)) /
            255.0f;
      } else {
        notes_.push_back("omero channel colour \"" + hex + "\" is not RRGGBB: white");
      }
    }
    if (c.contains("window") && c["window"].is_object()) {
      const json& w = c["window"];
      bool numbers = true;
      const auto num = [&](const char* k, double& v) {
        if (!w.contains(k)) return;
        if (w[k].is_number()) {
          v = w[k].get<double>();
        } else {
          notes_.push_back(which + " window." + k + " " + w[k].dump() +
                           " is not a number: the window is ignored");
          numbers = false;
        }
      };
      num("start", out.window.min);
      num("end", out.window.max);
      num("min", out.range.min);
      num("max", out.range.max);
      out.hasWindow = numbers && w.contains("start") && w.contains("end");
    }
    channels_.push_back(out);
  }
}

void ZarrStore::addLevel(const std::string& path, glm::dvec3 scale, glm::dvec3 translation) {
  ZarrLevel& lv = levels_.back();
  const std::string meta = format_ == 3 ? "zarr.json" : ".zarray";
  const std::string where = storage_->locate(path.empty() ? meta : path + "/" + meta);
  lv.path = path;
  for (int r = 0; r < 3; ++r) {
    const std::int64_t n = lv.array.shape[std::size_t(axis_[r])];
    if (n > std::numeric_limits<int>::max() / 2) {
      throw InputError(where + ": " + std::to_string(n) + " voxels along " + "xyz"[r] +
                       " is more than Tessera indexes");
    }
    lv.dims[r] = static_cast<int>(n);
    lv.chunk[r] =
        static_cast<int>(std::min<std::int64_t>(lv.array.chunks[std::size_t(axis_[r])], 1 << 30));
    if (!(scale[r] > 0.0) || !std::isfinite(scale[r])) {
      throw InputError(where + ": scale along " + "xyz"[r] + " is " + std::to_string(scale[r]) +
                       " (must be > 0)");
    }
  }
  lv.spacing = scale;
  lv.origin = translation;
  if (lv.array.converted) {
    notes_.push_back("level " + path + ": dtype " + lv.array.dtype + " is read as f32");
  }
}

int ZarrStore::timePoints() const {
  const int t = axis_[kT];
  return t >= 0 ? static_cast<int>(levels_.front().array.shape[std::size_t(t)]) : 1;
}

void ZarrStore::checkSelection() {
  const ZarrArrayMeta& a = levels_.front().array;
  const auto check = [&](int role, int value, const char* option, const char* axis) {
    const std::int64_t n = axis_[role] >= 0 ? a.shape[std::size_t(axis_[role])] : 1;
    if (value < 0 || value >= n) {
      throw InputError(storage_->describe() + ": " + option + " " + std::to_string(value) +
                       " is outside the store's " + std::to_string(n) + " " + axis +
                       (axis_[role] >= 0 ? "" : " (it has no such axis)"));
    }
  };
  check(kT, selection_.time, "--time", "time points");
  check(kC, selection_.channel, "--channel", "channels");
  for (const ZarrLevel& lv : levels_) {
    if (lv.array.target != a.target) {
      throw InputError(storage_->describe() + ": level " + lv.path + " has dtype " +
                       lv.array.dtype + ", level " + levels_.front().path + " " + a.dtype);
    }
  }
}

void ZarrStore::makeShape() {
  const ZarrLevel& fine = levels_.front();
  shape_ = Volume::shapeOnly(fine.dims, fine.array.target);
  shape_.setSpacing(fine.spacing);
  shape_.setDirection(direction_);
  shape_.setOrigin(fine.origin);
  shape_.setGeometrySource(
      "OME-NGFF " + version_ +
      " scale+translation; NGFF has no orientation: x,y,z taken as R,A,S (RAS+)" +
      (direction_ == glm::dmat3(1.0) ? "" : ", direction from tessera attributes"));
  shape_.setDescription("OME-Zarr " + storage_->describe() + (name_.empty() ? "" : " " + name_));
  // The value range: Tessera's own attribute (the level-0 range `convert`
  // measured), else omero's channel min/max, else the coarsest level's range
  // (one chunk in a full pyramid; a mean pyramid's extremes may lie beyond
  // it). The window: Tessera's own, else omero's start/end, else the value
  // range, as for the same data read from a file.
  auto pair = [](const json& j, const char* a, const char* b) -> std::optional<ValueRange> {
    if (j.contains(a) && j.contains(b) && j[a].is_number() && j[b].is_number()) {
      return ValueRange{j[a].get<double>(), j[b].get<double>()};
    }
    return std::nullopt;
  };
  auto array2 = [](const json& j, const char* key) -> std::optional<ValueRange> {
    if (j.contains(key) && j[key].is_array() && j[key].size() == 2 && j[key][0].is_number() &&
        j[key][1].is_number()) {
      return ValueRange{j[key][0].get<double>(), j[key][1].get<double>()};
    }
    return std::nullopt;
  };
  auto finite = [](const std::optional<ValueRange>& r, bool wide) {
    return r && std::isfinite(r->min) && std::isfinite(r->max) &&
           (wide ? r->min < r->max : r->min <= r->max);
  };
  std::optional<ValueRange> range, window;
  if (!attrsText_.empty()) {
    const json attrs = parseJson(attrsText_, attrsWhere_);
    const json ngff = parseJson(ngffText_, attrsWhere_);
    if (attrs.contains("tessera") && attrs["tessera"].is_object()) {
      range = array2(attrs["tessera"], "value_range");
      window = array2(attrs["tessera"], "window");
    }
    if (ngff.contains("omero") && ngff["omero"].is_object() && ngff["omero"].contains("channels")) {
      const json& ch = ngff["omero"]["channels"];
      const std::size_t c = std::size_t(selection_.channel);
      if (ch.is_array() && c < ch.size() && ch[c].contains("window") &&
          ch[c]["window"].is_object()) {
        const json& w = ch[c]["window"];
        if (!finite(range, false)) range = pair(w, "min", "max");
        if (!finite(window, true)) window = pair(w, "start", "end");
      }
    }
  }
  if (!finite(range, false)) {
    range.reset();
    const int coarse = levelCount() - 1;
    const glm::ivec3 d = levels_.back().dims;
    const std::uint64_t bytes = std::uint64_t(d.x) * std::uint64_t(d.y) * std::uint64_t(d.z) *
                                bytesPerVoxel(fine.array.target);
    if (bytes <= (64ull << 20)) range = readLevel(coarse).valueRange();
  }
  if (range) shape_.setValueRange(*range);
  // Set, not left to default: every box and level read carries it, so a
  // level renders with the same mapping as the whole (bricks, the reference).
  if (finite(window, true)) {
    shape_.setWindow(*window);
  } else if (range && range->max > range->min) {
    shape_.setWindow(*range);
  }
}

int ZarrStore::finestLevelWithin(std::uint64_t budgetBytes) const {
  for (int l = 0; l < levelCount(); ++l) {
    const ZarrLevel& lv = levels_[std::size_t(l)];
    const std::uint64_t voxels =
        std::uint64_t(lv.dims.x) * std::uint64_t(lv.dims.y) * std::uint64_t(lv.dims.z);
    const std::uint64_t need = voxels * bytesPerVoxel(lv.array.target) +
                               std::uint64_t(storage_->parallelism()) *
                                   (lv.array.chunkBytes() + lv.array.maxStoredChunkBytes());
    if (need <= budgetBytes) return l;
  }
  return -1;
}

int ZarrStore::finestLevelInHostBudget(const std::string& spec) const {
  const std::uint64_t budget = HostBudget::global().limitBytes();
  const int l = finestLevelWithin(budget);
  if (l < 0) {
    const ZarrLevel& coarse = level(levelCount() - 1);
    throw BudgetError(spec + ": even the coarsest level (" + std::to_string(coarse.dims.x) + "x" +
                      std::to_string(coarse.dims.y) + "x" + std::to_string(coarse.dims.z) +
                      ") does not fit the host budget " + formatBytes(budget));
  }
  return l;
}

int ZarrStore::channelCount() const {
  return axis_[kC] >= 0 ? static_cast<int>(levels_.front().array.shape[std::size_t(axis_[kC])]) : 1;
}

std::string ZarrStore::describe() const {
  return "OME-Zarr " + storage_->describe() + " (" +
         (version_.rfind("plain", 0) == 0 ? version_ : "NGFF " + version_) +
         (format_ == 3 ? " on Zarr v3" : "") + ", " + std::to_string(levelCount()) + " level" +
         (levelCount() == 1 ? "" : "s") + ", " + levels_.front().array.dtype + ", " +
         levels_.front().array.compressorText + ")";
}

Volume ZarrStore::readBox(int l, glm::ivec3 begin, glm::ivec3 end, const Progress& progress) const {
  const ZarrLevel& lv = level(l);
  for (int a = 0; a < 3; ++a) {
    if (begin[a] < 0 || end[a] > lv.dims[a] || begin[a] >= end[a]) {
      throw InputError(storage_->describe() + ": box [" + std::to_string(begin.x) + "," +
                       std::to_string(begin.y) + "," + std::to_string(begin.z) + ") - (" +
                       std::to_string(end.x) + "," + std::to_string(end.y) + "," +
                       std::to_string(end.z) + ") is empty or outside level " + std::to_string(l) +
                       "'s dims");
    }
  }
  const int workers = std::max(1, storage_->parallelism());
  HostBudget::global().check(
      std::uint64_t(end.x - begin.x) * std::uint64_t(end.y - begin.y) *
              std::uint64_t(end.z - begin.z) * bytesPerVoxel(lv.array.target) +
          std::uint64_t(workers) * (lv.array.chunkBytes() + lv.array.maxStoredChunkBytes()),
      storage_->describe() + " level " + std::to_string(l) + " box");
  Volume out = Volume::allocate(end - begin, lv.array.target, storage_->describe());
  out.setSpacing(lv.spacing);
  out.setDirection(direction_);
  out.setOrigin(lv.origin + direction_ * (lv.spacing * glm::dvec3(begin)));
  out.setGeometrySource(shape_.geometrySource());
  if (shape_.hasWindow()) out.setWindow(shape_.window());
  out.setDescription(shape_.description() + " level " + std::to_string(l));
  const glm::ivec3 c0 = begin / lv.chunk;
  const glm::ivec3 c1 = (end - 1) / lv.chunk + 1;
  std::vector<std::vector<std::int64_t>> chunks;
  for (int z = c0.z; z < c1.z; ++z) {
    for (int y = c0.y; y < c1.y; ++y) {
      for (int x = c0.x; x < c1.x; ++x) chunks.push_back({x, y, z});
    }
  }
  std::atomic<std::size_t> next{0};
  std::size_t done = 0;
  std::exception_ptr failure;
  std::mutex failureMutex;
  auto work = [&] {
    for (std::size_t i = next++; i < chunks.size(); i = next++) {
      try {
        readChunkInto(l, chunks[i], begin, end, out);
        if (progress) {
          const std::lock_guard lock(failureMutex);
          progress(++done, chunks.size());
        }
      } catch (...) {
        const std::lock_guard lock(failureMutex);
        if (!failure) failure = std::current_exception();
        next = chunks.size();
      }
    }
  };
  const int threads = static_cast<int>(std::min<std::size_t>(std::size_t(workers), chunks.size()));
  if (threads <= 1) {
    work();
  } else {
    // std::thread, joined by hand: the browser build's libc++ has no jthread.
    std::vector<std::thread> pool;
    const auto joinAll = [&] {
      for (std::thread& t : pool) t.join();
    };
    try {
      for (int t = 0; t < threads; ++t) pool.emplace_back(work);
    } catch (...) {
      next = chunks.size();
      joinAll();
      throw;
    }
    joinAll();
  }
  if (failure) std::rethrow_exception(failure);
  out.invalidateRange();
  return out;
}

struct ZarrStore::ShardIndex {
  std::vector<ZarrShardEntry> entries;
  std::uint64_t bytes = 0;  // the whole shard's
};

std::shared_ptr<const ZarrStore::ShardIndex> ZarrStore::shardIndex(const ZarrArrayMeta& m,
                                                                   const std::string& key) const {
  // One read per shard: a reader wanting an index being read waits for it.
  std::promise<std::shared_ptr<const ShardIndex>> mine;
  std::shared_future<std::shared_ptr<const ShardIndex>> pending;
  bool reader = false;
  {
    const std::lock_guard lock(shardMutex_);
    const auto it = shards_.find(key);
    if (it != shards_.end()) {
      pending = it->second;
    } else {
      // Indexes are small (16 B per inner chunk); a store of very many
      // shards starts over rather than grow without bound.
      if (shards_.size() >= 4096) shards_.clear();
      pending = mine.get_future().share();
      shards_[key] = pending;
      reader = true;
    }
  }
  if (!reader) return pending.get();
  try {
    const std::uint64_t n = m.shardIndexBytes();
    const auto r =
        storage_->getRange(key, m.indexAtEnd ? -std::int64_t(n) : 0, n, m.maxStoredShardBytes());
    std::shared_ptr<const ShardIndex> index;
    if (r) {
      auto built = std::make_shared<ShardIndex>();
      built->entries = parseShardIndex(m, r->bytes, r->total, storage_->locate(key));
      built->bytes = r->total;
      index = std::move(built);
    }
    mine.set_value(index);
    return index;
  } catch (...) {
    // Not remembered: the next reader asks again (a network may recover).
    {
      const std::lock_guard lock(shardMutex_);
      shards_.erase(key);
    }
    mine.set_exception(std::current_exception());
    throw;
  }
}

ZarrChunkCache::Chunk ZarrStore::decodeChunk(const ZarrArrayMeta& m, const std::string& key,
                                             std::int64_t inner) const {
  std::shared_ptr<const ShardIndex> index;
  if (inner >= 0) {
    index = shardIndex(m, key);
    if (!index || index->entries[std::size_t(inner)].missing()) return nullptr;  // fill_value
  }
  const std::string where =
      storage_->locate(key) + (inner >= 0 ? " (inner chunk " + std::to_string(inner) + ")" : "");
  const bool decoded = storage_->decodesChunks(m.compressor);
  for (int attempt = 0;; ++attempt) {
    std::optional<std::vector<std::byte>> stored;
    if (inner >= 0) {
      const ZarrShardEntry& e = index->entries[std::size_t(inner)];
      auto r = storage_->getRange(key, std::int64_t(e.offset), e.bytes, index->bytes);
      if (r) stored = std::move(r->bytes);
    } else {
      stored = storage_->get(key, m.maxStoredChunkBytes());
    }
    if (!stored) return nullptr;
    try {
      return std::make_shared<const std::vector<std::byte>>(
          decoded ? decodedZarrChunk(m, std::move(*stored), where)
                  : decodeZarrChunk(m, *stored, where));
    } catch (const InputError&) {
      // A network may have damaged the body: fetch it again.
      if (attempt >= storage_->refetches()) throw;
      storage_->forget(key);
    }
  }
}

std::uint64_t ZarrStore::allChunkBytes() const {
  std::uint64_t bytes = 0;
  for (const ZarrLevel& lv : levels_) {
    std::uint64_t chunks = 1;
    for (int r = kX; r <= kZ; ++r) {
      chunks *= std::uint64_t(lv.array.chunkCount(axis_[r]));
    }
    bytes += chunks * lv.array.chunkBytes();
  }
  return bytes;
}

std::vector<std::int64_t> ZarrStore::chunkIndexAt(int l,
                                                  const std::vector<std::int64_t>& spatial) const {
  const ZarrArrayMeta& m = levels_[std::size_t(l)].array;
  std::vector<std::int64_t> index(std::size_t(m.rank()), 0);
  for (int r = 0; r < 3; ++r) index[std::size_t(axis_[r])] = spatial[std::size_t(r)];
  const int sel[2] = {selection_.time, selection_.channel};
  for (int r = kT; r <= kC; ++r) {
    if (axis_[r] >= 0) index[std::size_t(axis_[r])] = sel[r - kT] / m.chunks[std::size_t(axis_[r])];
  }
  return index;
}

std::string ZarrStore::chunkKeyAt(int l, const std::vector<std::int64_t>& spatial) const {
  const ZarrLevel& lv = levels_[std::size_t(l)];
  return (lv.path.empty() ? "" : lv.path + "/") + lv.array.chunkKey(chunkIndexAt(l, spatial));
}

std::vector<std::string> ZarrStore::chunkKeys(int l, glm::ivec3 begin, glm::ivec3 end) const {
  const ZarrLevel& lv = level(l);
  const glm::ivec3 c0 = glm::max(begin, glm::ivec3(0)) / lv.chunk;
  const glm::ivec3 c1 = (glm::min(end, lv.dims) - 1) / lv.chunk + 1;
  std::vector<std::string> keys;
  for (int z = c0.z; z < c1.z; ++z) {
    for (int y = c0.y; y < c1.y; ++y) {
      for (int x = c0.x; x < c1.x; ++x) {
        std::string key = chunkKeyAt(l, {x, y, z});
        // A sharded level's inner chunks share their shard's key.
        if (!lv.array.sharded() || std::find(keys.begin(), keys.end(), key) == keys.end()) {
          keys.push_back(std::move(key));
        }
      }
    }
  }
  return keys;
}

bool ZarrStore::holdsReads(int l, glm::ivec3 begin, glm::ivec3 end,
                           const std::function<bool(const ZarrStoredRead&)>& holds) const {
  const ZarrLevel& lv = level(l);
  const ZarrArrayMeta& m = lv.array;
  const std::string prefix = lv.path.empty() ? "" : lv.path + "/";
  const glm::ivec3 c0 = glm::max(begin, glm::ivec3(0)) / lv.chunk;
  const glm::ivec3 c1 = (glm::min(end, lv.dims) - 1) / lv.chunk + 1;
  bool all = true;
  // Sharded: each shard's index once known (nullptr: an absent shard), or
  // not held yet (absent from the map's values: `pendingShards`).
  std::map<std::string, std::shared_ptr<const ShardIndex>> indexes;
  std::vector<std::string> pendingShards;
  for (int z = c0.z; z < c1.z; ++z) {
    for (int y = c0.y; y < c1.y; ++y) {
      for (int x = c0.x; x < c1.x; ++x) {
        const std::vector<std::int64_t> index = chunkIndexAt(l, {x, y, z});
        std::string key = prefix + m.chunkKey(index);
        if (!m.sharded()) {
          all = holds(ZarrStoredRead{.key = std::move(key)}) && all;
          continue;
        }
        if (std::find(pendingShards.begin(), pendingShards.end(), key) != pendingShards.end()) {
          continue;
        }
        auto it = indexes.find(key);
        if (it == indexes.end()) {
          bool known = false;
          {
            const std::lock_guard lock(shardMutex_);
            known = shards_.count(key) != 0;
          }
          const std::uint64_t n = m.shardIndexBytes();
          if (!known && !holds(ZarrStoredRead{.key = key,
                                              .whole = false,
                                              .offset = m.indexAtEnd ? -std::int64_t(n) : 0,
                                              .length = n})) {
            all = false;
            pendingShards.push_back(std::move(key));
            continue;
          }
          it = indexes.emplace(key, shardIndex(m, key)).first;
        }
        if (!it->second) continue;  // an absent shard: fill_value
        const ZarrShardEntry& e = it->second->entries[std::size_t(m.innerChunkIndex(index))];
        if (e.missing()) continue;
        all = holds(ZarrStoredRead{.key = std::move(key),
                                   .whole = false,
                                   .offset = std::int64_t(e.offset),
                                   .length = e.bytes}) &&
              all;
      }
    }
  }
  return all;
}

void ZarrStore::readChunkInto(int l, const std::vector<std::int64_t>& spatial, glm::ivec3 begin,
                              glm::ivec3 end, Volume& out) const {
  const ZarrLevel& lv = levels_[std::size_t(l)];
  const ZarrArrayMeta& m = lv.array;
  const int rank = m.rank();
  // The element strides inside a chunk (C order), and the selected time
  // point's and channel's offset in it.
  std::vector<std::int64_t> stride(std::size_t(rank), 1);
  for (int a = rank - 2; a >= 0; --a)
    stride[std::size_t(a)] = stride[std::size_t(a) + 1] * m.chunks[std::size_t(a) + 1];
  std::int64_t base = 0;
  const int sel[2] = {selection_.time, selection_.channel};
  for (int r = kT; r <= kC; ++r) {
    if (axis_[r] < 0) continue;
    base += (sel[r - kT] % m.chunks[std::size_t(axis_[r])]) * stride[std::size_t(axis_[r])];
  }
  const std::vector<std::int64_t> index = chunkIndexAt(l, spatial);
  const std::string key = (lv.path.empty() ? "" : lv.path + "/") + m.chunkKey(index);
  const std::int64_t inner = m.sharded() ? std::int64_t(m.innerChunkIndex(index)) : -1;
  const glm::ivec3 origin =
      glm::ivec3(int(spatial[0]), int(spatial[1]), int(spatial[2])) * lv.chunk;
  const glm::ivec3 lo = glm::max(begin, origin);
  const glm::ivec3 hi = glm::min(end, origin + lv.chunk);
  const ZarrChunkCache::Chunk raw =
      chunks_->get(inner >= 0 ? key + "#" + std::to_string(inner) : key,
                   [&] { return decodeChunk(m, key, inner); });
  const std::size_t bpv = bytesPerVoxel(m.target);
  const std::int64_t sx = stride[std::size_t(axis_[kX])];
  const std::int64_t sy = stride[std::size_t(axis_[kY])];
  const std::int64_t sz = stride[std::size_t(axis_[kZ])];
  const bool direct = raw && !m.converted && sx == 1 &&
                      (m.itemSize == 1 || m.bigEndian == (std::endian::native == std::endian::big));
  for (int z = lo.z; z < hi.z; ++z) {
    for (int y = lo.y; y < hi.y; ++y) {
      std::byte* dst =
          out.bytes().data() + out.index(lo.x - begin.x, y - begin.y, z - begin.z) * bpv;
      const std::size_t n = std::size_t(hi.x - lo.x);
      if (!raw) {
        for (std::size_t i = 0; i < n; ++i) {
          switch (m.target) {
            case ScalarType::U8: {
              const auto v = roundedFill<std::uint8_t>(m.fill);
              std::memcpy(dst + i, &v, 1);
              break;
            }
            case ScalarType::U16: {
              const auto v = roundedFill<std::uint16_t>(m.fill);
              std::memcpy(dst + 2 * i, &v, 2);
              break;
            }
            case ScalarType::I16: {
              const auto v = roundedFill<std::int16_t>(m.fill);
              std::memcpy(dst + 2 * i, &v, 2);
              break;
            }
            case ScalarType::F32: {
              const auto v = static_cast<float>(m.fill);
              std::memcpy(dst + 4 * i, &v, 4);
              break;
            }
          }
        }
        continue;
      }
      const std::int64_t first =
          base + (z - origin.z) * sz + (y - origin.y) * sy + (lo.x - origin.x) * sx;
      const std::byte* src = raw->data() + first * m.itemSize;
      if (direct) {
        std::memcpy(dst, src, n * bpv);
        continue;
      }
      for (std::size_t i = 0; i < n; ++i) {
        const std::byte* e = src + std::int64_t(i) * sx * m.itemSize;
        if (m.converted) {
          const float v = static_cast<float>(elementValue(e, m));
          std::memcpy(dst + 4 * i, &v, 4);
        } else {
          // Same type, other byte order or axis order: copy, swapped if needed.
          std::byte b[4];
          std::memcpy(b, e, bpv);
          if (m.itemSize > 1 && m.bigEndian != (std::endian::native == std::endian::big)) {
            std::reverse(b, b + bpv);
          }
          std::memcpy(dst + bpv * i, b, bpv);
        }
      }
    }
  }
}

}  // namespace tessera
