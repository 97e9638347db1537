// Device profiles: the built-in table (the papers' devices and generic API
// classes) and the JSON form of a profile (DeviceProfile.h).
#include "tessera/gpu/DeviceProfile.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"

namespace tessera::gpu {

namespace {

// ordered_json keeps the keys in the order the header documents, so that a
// printed profile reads like the files users write.
using Json = nlohmann::ordered_json;

constexpr std::uint64_t kMiB = 1024ull * 1024;
constexpr int kUnlimited = DeviceProfile::kUnlimited;

// A budget above this many MiB would overflow 64-bit byte counts.
constexpr double kMaxBudgetMiB = 1ull << 43;

// A profile is a few hundred bytes; refuse to slurp something else by mistake.
constexpr std::uintmax_t kMaxProfileFileBytes = 1ull << 20;

const char* const kKeys[] = {"name",
                             "note",
                             "api",
                             "max_2d_texture_size",
                             "max_3d_texture_size",
                             "texture_units",
                             "texture_budget_mb",
                             "host_budget_mb",
                             "float_render_targets"};

std::vector<DeviceProfile> makeBuiltins() {
  // Every field is spelled out per profile so that a row can be checked
  // against its note without knowing the struct's defaults.
  return {
      {.name = "axim-x51v",
       .note = "Moser & Weiskopf 2008 §3-4: Dell Axim X51v, Intel 2700G with 16 MB video RAM, "
               "64 MB RAM, OpenGL ES 1.0 (modelled as gles2), no 3D textures, 'dual texturing' "
               "= 2 units; max 1024² is assumed (PowerVR MBX-class; the paper gives none)",
       .api = ApiLevel::Gles2,
       .max2DTextureSize = 1024,
       .max3DTextureSize = 0,
       .textureUnits = 2,
       .textureBudget = 16 * kMiB,
       .hostBudget = 64 * kMiB,
       .floatRenderTargets = false},
      {.name = "ipad2",
       .note = "Noguera & Jiménez 2012 §4.1: iPad 2, PowerVR SGX543MP2, OpenGL ES 2.0, 2048², "
               "8 units; 128 MiB holds their six RGBA 2048² textures (96 MiB) plus the TF; "
               "host 256 MiB of its 512 MB RAM",
       .api = ApiLevel::Gles2,
       .max2DTextureSize = 2048,
       .max3DTextureSize = 0,
       .textureUnits = 8,
       .textureBudget = 128 * kMiB,
       .hostBudget = 256 * kMiB,
       .floatRenderTargets = false},
      {.name = "webgl1-desktop-2012",
       .note = "Noguera & Jiménez 2012 §4.2: WebGL 1 (Opera 11.50) on a GeForce 8800GT, 8192², "
               "16 units; texture budget = the card's 512 MB, host 2 GiB of the PC's 4 GB",
       .api = ApiLevel::Gles2,
       .max2DTextureSize = 8192,
       .max3DTextureSize = 0,
       .textureUnits = 16,
       .textureBudget = 512 * kMiB,
       .hostBudget = 2048 * kMiB,
       .floatRenderTargets = false},
      {.name = "nexus7",
       .note = "Nexus 7 (2013), the OpenGL ES 3.0 tablet of Sarfaraz & Shaban 2015: published "
               "GLES caps of its Adreno 320 (4096² 2D, 1024³ 3D, 16 units); 2 GB RAM -> 512 MiB "
               "textures, 512 MiB host; ES 3.0 does not require float render targets",
       .api = ApiLevel::Gles3,
       .max2DTextureSize = 4096,
       .max3DTextureSize = 1024,
       .textureUnits = 16,
       .textureBudget = 512 * kMiB,
       .hostBudget = 512 * kMiB,
       .floatRenderTargets = false},
      {.name = "shield-k1",
       .note = "Schultz 2016 §4-5: NVIDIA SHIELD Tablet, Tegra K1, OpenGL ES 3.0 app on an ES "
               "3.1-class GPU, 2 GB shared memory -> 1 GiB textures, largeHeap 469 MB host "
               "(§5.1); 16384² / 4096³ are Kepler desktop limits; 16 units assumed",
       .api = ApiLevel::Gles3,
       .max2DTextureSize = 16384,
       .max3DTextureSize = 4096,
       .textureUnits = 16,
       .textureBudget = 1024 * kMiB,
       .hostBudget = 469 * kMiB,
       .floatRenderTargets = true},
      {.name = "gles2",
       .note = "Generic OpenGL ES 2.0 GPU: 2048², 8 units (the spec's unit minimum; 2048² is the "
               "practical floor of ES 2.0 GPUs, the spec asks only 64²), no 3D textures, 256 MiB",
       .api = ApiLevel::Gles2,
       .max2DTextureSize = 2048,
       .max3DTextureSize = 0,
       .textureUnits = 8,
       .textureBudget = 256 * kMiB,
       .hostBudget = 0,
       .floatRenderTargets = false},
      {.name = "webgl1",
       .note = "Generic WebGL 1 browser (ES 2.0 semantics, no 3D textures): 4096², 16 units, "
               "512 MiB, a conservative desktop/laptop; cf. Noguera & Jiménez 2012 §4.2",
       .api = ApiLevel::Gles2,
       .max2DTextureSize = 4096,
       .max3DTextureSize = 0,
       .textureUnits = 16,
       .textureBudget = 512 * kMiB,
       .hostBudget = 0,
       .floatRenderTargets = false},
      {.name = "gles3",
       .note = "Generic OpenGL ES 3.0 GPU at the spec's minimum maxima: 2048² 2D, 256³ 3D, "
               "16 units; 512 MiB; no float render targets (EXT_color_buffer_float is optional)",
       .api = ApiLevel::Gles3,
       .max2DTextureSize = 2048,
       .max3DTextureSize = 256,
       .textureUnits = 16,
       .textureBudget = 512 * kMiB,
       .hostBudget = 0,
       .floatRenderTargets = false},
      {.name = "webgl2",
       .note = "Generic WebGL 2 desktop browser: 8192² 2D, 2048³ 3D (what Chrome/ANGLE reports, "
               "ENVIRONMENT.md), 16 units, 1 GiB",
       .api = ApiLevel::Gles3,
       .max2DTextureSize = 8192,
       .max3DTextureSize = 2048,
       .textureUnits = 16,
       .textureBudget = 1024 * kMiB,
       .hostBudget = 0,
       .floatRenderTargets = true},
      {.name = "native",
       .note = "No restriction: whatever the context reports, no budgets beyond the host's",
       .api = ApiLevel::Gles3,
       .max2DTextureSize = kUnlimited,
       .max3DTextureSize = kUnlimited,
       .textureUnits = kUnlimited,
       .textureBudget = 0,
       .hostBudget = 0,
       .floatRenderTargets = true},
  };
}

std::string builtinNameList() {
  std::string s;
  for (const DeviceProfile& p : DeviceProfile::builtins()) {
    if (!s.empty()) s += ", ";
    s += p.name;
  }
  return s;
}

// nlohmann's messages start with "[json.exception.parse_error.101] "; the id
// means nothing to a user.
std::string withoutExceptionId(const std::string& message) {
  const auto close = message.find("] ");
  return message.rfind("[json.exception.", 0) == 0 && close != std::string::npos
             ? message.substr(close + 2)
             : message;
}

class ProfileReader {
 public:
  ProfileReader(const Json& j, const std::string& what) : j_(j), what_(what) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError("device profile " + what_ + ": " + problem);
  }

  bool has(const char* key) const { return j_.contains(key); }

  std::string string(const char* key) const {
    const Json& v = j_.at(key);
    if (!v.is_string()) fail(std::string("\"") + key + "\" must be a string, got " + v.dump());
    return v.get<std::string>();
  }

  // A texture size or unit count: an integer in [minimum, 2^30] or "unlimited".
  int limit(const char* key, int minimum) const {
    const Json& v = j_.at(key);
    if (v.is_string() && v.get<std::string>() == "unlimited") return kUnlimited;
    const std::string expected =
        std::string("\"") + key + "\" must be an integer " + ">= " + std::to_string(minimum) +
        (minimum == 0 ? " (0 = none)" : "") + " or \"unlimited\", got " + v.dump();
    if (!v.is_number_integer()) fail(expected);
    // An unsigned JSON integer may not fit a long long; it is too large anyway.
    if (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t{kUnlimited}) {
      fail(expected + " (the largest is 1073741824)");
    }
    const long long n = v.get<long long>();
    if (n < minimum) fail(expected);
    if (n > kUnlimited) fail(expected + " (the largest is 1073741824)");
    return static_cast<int>(n);
  }

  // A budget in MiB (fractions allowed, 0 = unlimited) as bytes.
  std::uint64_t budget(const char* key) const {
    const Json& v = j_.at(key);
    const std::string expected = std::string("\"") + key +
                                 "\" must be a number of MiB >= 0 (0 = unlimited), got " + v.dump();
    if (!v.is_number()) fail(expected);
    const double mib = v.get<double>();
    if (!(mib >= 0.0) || mib > kMaxBudgetMiB) fail(expected);
    // Multiplying by 2^20 is exact in binary floating point, so a budget
    // written by toJson() reads back to the same byte count.
    return static_cast<std::uint64_t>(std::llround(mib * static_cast<double>(kMiB)));
  }

  bool boolean(const char* key) const {
    const Json& v = j_.at(key);
    if (!v.is_boolean())
      fail(std::string("\"") + key + "\" must be true or false, got " + v.dump());
    return v.get<bool>();
  }

 private:
  const Json& j_;
  const std::string& what_;
};

Json limitJson(int value) {
  return value >= kUnlimited ? Json("unlimited") : Json(value);
}

Json budgetJson(std::uint64_t bytes) {
  if (bytes % kMiB == 0) return Json(bytes / kMiB);
  return Json(static_cast<double>(bytes) / static_cast<double>(kMiB));
}

}  // namespace

const char* apiLevelName(ApiLevel api) {
  return api == ApiLevel::Gles2 ? "gles2" : "gles3";
}

const std::vector<DeviceProfile>& DeviceProfile::builtins() {
  static const std::vector<DeviceProfile> profiles = makeBuiltins();
  return profiles;
}

DeviceProfile DeviceProfile::find(const std::string& nameOrPath) {
  for (const DeviceProfile& p : builtins()) {
    if (p.name == nameOrPath) return p;
  }
  const std::filesystem::path path(nameOrPath);
  std::error_code ec;
  if (path.extension() == ".json" && std::filesystem::is_regular_file(path, ec)) {
    return load(path);
  }
  throw InputError(
      "unknown device profile '" + nameOrPath +
      "': not a built-in and not an existing .json file; built-in profiles: " + builtinNameList());
}

DeviceProfile DeviceProfile::load(const std::filesystem::path& path) {
  const std::string what = path.string();
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError("device profile " + what + ": cannot read: " + ec.message());
  if (size > kMaxProfileFileBytes) {
    throw InputError("device profile " + what + ": " + std::to_string(size) +
                     " bytes is too large for a profile (at most 1 MiB)");
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in.good() && !in.eof()) throw InputError("device profile " + what + ": read failed");
  return fromJson(text.str(), what);
}

DeviceProfile DeviceProfile::fromJson(const std::string& text, const std::string& what) {
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::exception& e) {
    // parse_error, and out_of_range for numbers no double can hold.
    throw InputError("device profile " + what +
                     ": malformed JSON: " + withoutExceptionId(e.what()));
  }
  const ProfileReader r(j, what);
  if (!j.is_object()) r.fail("expected a JSON object, got " + std::string(j.type_name()));

  const std::set<std::string> known(std::begin(kKeys), std::end(kKeys));
  for (const auto& item : j.items()) {
    if (known.count(item.key()) == 0) {
      std::string keys;
      for (const char* k : kKeys) keys += (keys.empty() ? "" : ", ") + std::string(k);
      r.fail("unknown key \"" + item.key() + "\" (known keys: " + keys + ")");
    }
  }
  for (const char* required : {"name", "api"}) {
    if (!r.has(required)) r.fail(std::string("missing \"") + required + "\"");
  }

  DeviceProfile p;
  p.name = r.string("name");
  if (p.name.empty()) r.fail("\"name\" is empty");
  for (const unsigned char c : p.name) {
    // The name is typed on command lines and printed in tables.
    if (c <= ' ') r.fail("\"name\" must not contain spaces or control characters");
  }
  if (r.has("note")) p.note = r.string("note");
  if (p.note.find_first_of("\r\n") != std::string::npos) r.fail("\"note\" must be one line");

  const std::string api = r.string("api");
  if (api == "gles2") {
    p.api = ApiLevel::Gles2;
  } else if (api == "gles3") {
    p.api = ApiLevel::Gles3;
  } else {
    r.fail("\"api\" must be \"gles2\" or \"gles3\", got \"" + api + "\"");
  }
  const bool gles2 = p.api == ApiLevel::Gles2;

  p.max2DTextureSize =
      r.has("max_2d_texture_size") ? r.limit("max_2d_texture_size", 1) : kUnlimited;
  // Left out, a gles3 profile keeps the context's 3D limit; 0 turns 3D
  // textures off (to force the 2D layouts on an ES 3 device).
  p.max3DTextureSize =
      r.has("max_3d_texture_size") ? r.limit("max_3d_texture_size", 0) : (gles2 ? 0 : kUnlimited);
  if (gles2 && p.max3DTextureSize != 0) {
    r.fail("\"max_3d_texture_size\" must be 0 for api gles2 (OpenGL ES 2.0 has no 3D textures)");
  }
  p.textureUnits = r.has("texture_units") ? r.limit("texture_units", 1) : kUnlimited;
  p.textureBudget = r.has("texture_budget_mb") ? r.budget("texture_budget_mb") : 0;
  p.hostBudget = r.has("host_budget_mb") ? r.budget("host_budget_mb") : 0;
  p.floatRenderTargets = r.has("float_render_targets") ? r.boolean("float_render_targets") : !gles2;
  if (gles2 && p.floatRenderTargets) {
    // A contradiction in the file, not something to clamp silently.
    r.fail(
        "\"float_render_targets\" must be false for api gles2 (OpenGL ES 2.0 cannot render to "
        "float textures)");
  }
  return p;
}

std::string DeviceProfile::toJson() const {
  Json j;
  j["name"] = name;
  j["note"] = note;
  j["api"] = apiLevelName(api);
  j["max_2d_texture_size"] = limitJson(max2DTextureSize);
  j["max_3d_texture_size"] = limitJson(max3DTextureSize);
  j["texture_units"] = limitJson(textureUnits);
  j["texture_budget_mb"] = budgetJson(textureBudget);
  j["host_budget_mb"] = budgetJson(hostBudget);
  j["float_render_targets"] = floatRenderTargets;
  return j.dump(2);
}

}  // namespace tessera::gpu
