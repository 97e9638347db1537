// The specifications' own example documents, as published (sources and
// licences: tests/data/ngff-examples/README.md): OME-NGFF 0.5's examples
// and its schema test suites (valid and invalid `ome` attributes), the
// spec's "omero" section, and the Zarr v3 core spec's example array and
// group documents and the sharding codec's example. Each group document
// is put into an in-memory store whose arrays match its datasets; what
// Tessera reads is checked value by value, and every refusal is one line
// that names what is wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/io/ZarrArray.h"
#include "tessera/io/ZarrStorage.h"
#include "tessera/io/ZarrStore.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path examples() {
  return fs::path(TESSERA_TEST_DATA_DIR) / "ngff-examples";
}

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  EXPECT_TRUE(in) << p;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The NGFF examples are rendered in the spec as JSON with `//` comments,
// its "omero" section with `#` ones: drop them outside strings, as the
// spec's pages do before showing them.
std::string withoutComments(const std::string& s, const std::string& marker) {
  std::string out;
  bool inString = false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (inString) {
      out += c;
      if (c == '\\' && i + 1 < s.size()) {
        out += s[++i];
      } else if (c == '"') {
        inString = false;
      }
    } else if (s.compare(i, marker.size(), marker) == 0) {
      while (i < s.size() && s[i] != '\n') ++i;
      out += '\n';
    } else {
      inString = c == '"';
      out += c;
    }
  }
  return out;
}

// The Zarr spec's examples have trailing commas (`"endian": "little",}`),
// which JSON does not allow: the tests that need the rest drop them.
std::string withoutTrailingCommas(const std::string& s) {
  return std::regex_replace(s, std::regex(R"(,(\s*[}\]]))"), "$1");
}

std::vector<std::byte> bytesOf(const std::string& s) {
  std::vector<std::byte> b(s.size());
  std::memcpy(b.data(), s.data(), s.size());
  return b;
}

// j[key] when j is an object holding a string there, else "".
std::string stringAt(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j.at(key).is_string()) return "";
  return j.at(key).get<std::string>();
}

// A v3 store holding `group` as its zarr.json and, for every dataset of
// its first multiscales, a uint8 array whose shape fits the axes: space
// axes 16 voxels halved per level, t `times`, c `channels`, other axes 2.
std::shared_ptr<MemoryStorage> storeOf(const json& group, std::int64_t times = 2,
                                       std::int64_t channels = 3) {
  auto m = std::make_shared<MemoryStorage>("mem://example.ome.zarr");
  m->put("zarr.json", bytesOf(group.dump()));
  const json attributes = group.contains("attributes") ? group["attributes"] : json();
  const json ome =
      attributes.is_object() && attributes.contains("ome") ? attributes["ome"] : json();
  if (!ome.is_object() || !ome.contains("multiscales") || !ome["multiscales"].is_array() ||
      ome["multiscales"].empty()) {
    return m;
  }
  const json& ms = ome["multiscales"][0];
  std::vector<std::string> kinds;  // "space", "time", "channel", other
  if (ms.contains("axes") && ms["axes"].is_array()) {
    for (const json& a : ms["axes"]) {
      const std::string name = stringAt(a, "name");
      std::string type = stringAt(a, "type");
      if (type.empty() && (name == "x" || name == "y" || name == "z")) type = "space";
      kinds.push_back(type);
    }
  } else {
    kinds = {"space", "space", "space"};
  }
  if (kinds.empty()) kinds = {"space", "space", "space"};
  if (!ms.contains("datasets") || !ms["datasets"].is_array()) return m;
  int level = 0;
  for (const json& d : ms["datasets"]) {
    if (!d.is_object() || !d.contains("path") || !d["path"].is_string()) continue;
    std::vector<std::int64_t> shape;
    for (const std::string& k : kinds) {
      shape.push_back(k == "space"     ? std::max<std::int64_t>(16 >> level, 1)
                      : k == "time"    ? times
                      : k == "channel" ? channels
                                       : 2);
    }
    m->put(d["path"].get<std::string>() + "/zarr.json",
           bytesOf(zarrJsonArray(shape, shape, {}, ScalarType::U8, ZarrCompressor::None)));
    ++level;
  }
  return m;
}

json groupOf(const json& attributes) {
  return {{"zarr_format", 3}, {"node_type", "group"}, {"attributes", attributes}};
}

// "" when the store opens, else the error; `notes` gets the store's notes.
std::string openError(const std::shared_ptr<MemoryStorage>& m,
                      std::vector<std::string>* notes = nullptr) {
  try {
    const ZarrStore store(m);
    if (notes) *notes = store.notes();
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

TEST(ZarrSpecExamples, Ngff05MultiscalesExampleReadsItsAxesUnitsScalesAndType) {
  const std::string text =
      readText(examples() / "ngff-0.5/examples/multiscales_strict/multiscales_example.json");
  const json group = json::parse(withoutComments(text, "//"));
  const ZarrStore store(storeOf(group));
  ASSERT_EQ(store.levelCount(), 3);
  EXPECT_EQ(store.zarrFormat(), 3);
  EXPECT_EQ(store.timePoints(), 2);
  EXPECT_EQ(store.channelCount(), 3);
  EXPECT_EQ(store.reduction(), "gaussian");
  // 0.5, 1 and 2 micrometer per level, in mm; the multiscales-wide scale
  // (0.1 on t) leaves space alone.
  const double um = 1e-3;
  for (int l = 0; l < 3; ++l) {
    const double s = 0.5 * um * double(1 << l);
    EXPECT_NEAR(store.level(l).spacing.x, s, 1e-12) << l;
    EXPECT_NEAR(store.level(l).spacing.y, s, 1e-12) << l;
    EXPECT_NEAR(store.level(l).spacing.z, s, 1e-12) << l;
    EXPECT_EQ(store.level(l).dims, glm::ivec3(16 >> l)) << l;
    EXPECT_EQ(store.level(l).path, std::to_string(l));
  }
  EXPECT_NE(store.describe().find("0.5"), std::string::npos) << store.describe();
  EXPECT_NE(store.describe().find("example"), std::string::npos) << store.describe();
}

TEST(ZarrSpecExamples, TheSpecsOmeroSectionGivesTheChannelsColourWindowAndState) {
  const std::string omero =
      withoutComments("{" + readText(examples() / "ngff-0.5/omero-section.txt") + "}", "#");
  json group = json::parse(withoutComments(
      readText(examples() / "ngff-0.5/examples/multiscales_strict/multiscales_example.json"),
      "//"));
  group["attributes"]["ome"]["omero"] = json::parse(omero);
  const ZarrStore store(storeOf(group, 2, 1));
  ASSERT_EQ(store.channels().size(), 1u);
  const ZarrChannel& c = store.channels()[0];
  EXPECT_EQ(c.label, "LaminB1");
  EXPECT_EQ(c.color, glm::vec3(0, 0, 1));  // "0000FF"
  EXPECT_TRUE(c.active);
  ASSERT_TRUE(c.hasWindow);
  EXPECT_EQ(c.window.min, 0.0);
  EXPECT_EQ(c.window.max, 1500.0);
  EXPECT_EQ(c.range.min, 0.0);
  EXPECT_EQ(c.range.max, 65535.0);
  EXPECT_EQ(store.shape().window().max, 1500.0);  // the default window
}

TEST(ZarrSpecExamples, Ngff05ExamplesTesseraCannotShowAreRefusedInOneLine) {
  struct Case {
    const char* file;
    const char* expected;
  } cases[] = {
      // A 2D image (y, x) with a multiscales-wide scale: valid NGFF, not a volume.
      {"multiscales_strict/multiscales_transformations.json",
       "2 axes; a volume needs 3 (z, y, x) to 5 (t, c, z, y, x)"},
      // Collections that point at images in sub-groups.
      {"ome/series-2.json", "a Zarr v3 group without OME-NGFF multiscales"},
      {"bf2raw/image.json", "a Zarr v3 group without OME-NGFF multiscales"},
  };
  for (const Case& c : cases) {
    const json group =
        json::parse(withoutComments(readText(examples() / "ngff-0.5/examples" / c.file), "//"));
    const std::string error = openError(storeOf(group));
    EXPECT_NE(error.find(c.expected), std::string::npos) << c.file << ": " << error;
    EXPECT_NE(error.find("mem://example.ome.zarr/zarr.json"), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

// A suite case as a volume reader sees it: most cases are 2D (y, x),
// which Tessera refuses before it reaches what the case is about, so a z
// space axis (the unit of the others) is put in front and every scale and
// translation gets a leading 1 and 0. Cases with other than 2 axes are
// left as they are.
json liftedTo3d(json attrs) {
  if (!attrs.contains("ome") || !attrs["ome"].contains("multiscales") ||
      !attrs["ome"]["multiscales"].is_array()) {
    return attrs;
  }
  auto lift = [](json& list) {
    if (!list.is_array()) return;
    for (json& t : list) {
      if (!t.is_object()) continue;
      if (t.contains("scale") && t["scale"].is_array()) t["scale"].insert(t["scale"].begin(), 1.0);
      if (t.contains("translation") && t["translation"].is_array()) {
        t["translation"].insert(t["translation"].begin(), 0.0);
      }
    }
  };
  for (json& ms : attrs["ome"]["multiscales"]) {
    if (!ms.is_object() || !ms.contains("axes") || !ms["axes"].is_array() ||
        ms["axes"].size() != 2) {
      continue;
    }
    json z = {{"name", "z"}, {"type", "space"}};
    for (const json& a : ms["axes"]) {
      if (a.is_object() && a.contains("unit")) z["unit"] = a["unit"];
    }
    ms["axes"].insert(ms["axes"].begin(), z);
    if (ms.contains("coordinateTransformations")) lift(ms["coordinateTransformations"]);
    if (ms.contains("datasets") && ms["datasets"].is_array()) {
      for (json& d : ms["datasets"]) {
        if (d.is_object() && d.contains("coordinateTransformations")) {
          lift(d["coordinateTransformations"]);
        }
      }
    }
  }
  return attrs;
}

// The NGFF 0.5 schema test suites (JSON-Schema-Test-Suite style): each
// case's `data` is a group's attributes. As published, every invalid case
// is refused, and so are the valid ones that are not volumes (2D, an
// "angle" axis). Lifted to 3D, the valid cases with t/c/z/y/x axes open
// and the invalid ones are refused for what they are about; each refusal
// is one line naming the key.
TEST(ZarrSpecExamples, Ngff05SchemaSuitesValidCasesOpenInvalidOnesAreRefusedInOneLine) {
  // formerly-name -> a part of the expected error once lifted ("" = opens;
  // "note:..." = opens with that note: omero is rendering metadata, the
  // voxels are still right, so a bad colour or window is said, not fatal).
  const std::map<std::string, std::string> expected = {
      {"image_suite.json:valid/mismatch_axes_units.json",
       "axes need x, y and z (a 2D image is not a volume)"},
      {"image_suite.json:valid/untyped_axes.json", "axis \"angle\" is not one of t, c, z, y, x"},
      {"image_suite.json:valid/invalid_axis_units.json", ""},
      {"image_suite.json:valid/missing_name.json", ""},
      {"image_suite.json:valid/custom_type_axes.json",
       "axis \"angle\" is not one of t, c, z, y, x"},
      {"image_suite.json:invalid/duplicate_axes.json",
       "axis \"x\" is not one of t, c, z, y, x (each at most once)"},
      {"image_suite.json:invalid/missing_space_axes.json", "axes need x, y and z"},
      {"image_suite.json:invalid/invalid_transformation_type.json",
       "dataset \"0\" coordinateTransformations must be one \"scale\", then at most one "
       "\"translation\" (OME-NGFF 0.5); got [{\"scale\""},
      {"image_suite.json:invalid/missing_scale.json",
       "dataset \"0\" coordinateTransformations must be one \"scale\", then at most one "
       "\"translation\" (OME-NGFF 0.5); got [{\"translation\""},
      {"image_suite.json:invalid/too_many_axes.json", "6 axes; a volume needs 3 (z, y, x) to 5"},
      {"image_suite.json:invalid/invalid_channels_color.json",
       "note:omero channel 0 colour 255 is not an \"RRGGBB\" string: white"},
      {"image_suite.json:invalid/missing_axes_name.json",
       "axis {\"type\":\"space\",\"unit\":\"micron\"} has no name"},
      {"image_suite.json:invalid/invalid_axes_count.json",
       "1 axes; a volume needs 3 (z, y, x) to 5"},
      {"image_suite.json:invalid/one_space_axes.json", "axes need x, y and z"},
      {"image_suite.json:invalid/invalid_path.json", "\"path\":0} has no \"path\""},
      {"image_suite.json:invalid/invalid_multiscales_transformations.json",
       "[1.0,\"invalid\"],\"type\":\"scale\"} needs \"scale\" with 3 numbers"},
      {"image_suite.json:invalid/missing_transformations.json",
       "dataset \"0\" coordinateTransformations must be one \"scale\", then at most one "
       "\"translation\" (OME-NGFF 0.5); got none"},
      {"image_suite.json:invalid/no_datasets.json", "multiscales[0] has no \"datasets\""},
      {"image_suite.json:invalid/missing_datasets.json", "multiscales[0] has no \"datasets\""},
      {"image_suite.json:invalid/missing_axes.json",
       "needs \"scale\" with 5 numbers (one per axis)"},
      {"image_suite.json:invalid/invalid_axis_type.json",
       "axis \"y\" has type \"invalid\"; x, y and z are \"space\" axes"},
      {"image_suite.json:invalid/duplicate_scale.json",
       "dataset \"0\" coordinateTransformations must be one \"scale\", then at most one "
       "\"translation\" (OME-NGFF 0.5); got [{\"scale\":[1.0,1,1],\"type\":\"scale\"},{\"scale\""},
      {"image_suite.json:invalid/no_axes.json", "needs \"scale\" with 5 numbers (one per axis)"},
      {"image_suite.json:invalid/too_many_space_axes.json",
       "axis \"X\" is not one of t, c, z, y, x"},
      {"image_suite.json:invalid/no_multiscales.json",
       "\"multiscales\" must be a non-empty list of objects"},
      {"image_suite.json:invalid/invalid_channels_window.json",
       "note:omero channel 0 window.end \"100\" is not a number: the window is ignored"},
      {"image_suite.json:invalid/empty_transformations.json",
       "dataset \"0\" coordinateTransformations must be one \"scale\", then at most one "
       "\"translation\" (OME-NGFF 0.5); got []"},
      {"image_suite.json:invalid/missing_path.json", "}]} has no \"path\""},
      {"strict_image_suite.json:valid_strict/multiscales_example.json", ""},
      {"strict_image_suite.json:valid_strict/multiscales_transformations.json", ""},
      {"strict_image_suite.json:valid_strict/image_metadata.json", ""},
      {"strict_image_suite.json:valid_strict/image.json", ""},
      {"strict_image_suite.json:valid_strict/image_omero.json", ""},
  };
  int opened = 0, refused = 0;
  for (const char* suite : {"image_suite.json", "strict_image_suite.json"}) {
    const json doc = json::parse(readText(examples() / "ngff-0.5/tests" / suite));
    for (const json& t : doc["tests"]) {
      const std::string name = std::string(suite) + ":" + t["formerly"].get<std::string>();
      const bool valid = t["valid"].get<bool>();
      const std::string published = openError(storeOf(groupOf(t["data"])));
      std::vector<std::string> notes;
      const std::string error = openError(storeOf(groupOf(liftedTo3d(t["data"]))), &notes);
      std::printf("%-58s %s | %s | %s\n", name.c_str(), valid ? "valid  " : "invalid",
                  published.empty() ? "opens" : published.c_str(),
                  error.empty() ? "opens" : error.c_str());
      if (!valid) {
        EXPECT_NE(published, "") << name << " is invalid";
      }
      EXPECT_EQ(published.find('\n'), std::string::npos) << name << ": " << published;
      const auto e = expected.find(name);
      if (e == expected.end()) {
        ADD_FAILURE() << name << " has no expectation; got: " << error;
        continue;
      }
      if (e->second.empty() || e->second.rfind("note:", 0) == 0) {
        EXPECT_EQ(error, "") << name;
        if (!e->second.empty()) {
          const std::string note = e->second.substr(5);
          EXPECT_TRUE(std::any_of(notes.begin(), notes.end(),
                                  [&](const std::string& n) { return n == note; }))
              << name << " lacks the note: " << note;
        }
        ++opened;
      } else {
        EXPECT_NE(error.find(e->second), std::string::npos) << name << ": " << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << name << ": " << error;
        ++refused;
      }
    }
  }
  EXPECT_EQ(opened + refused, static_cast<int>(expected.size()));
  EXPECT_EQ(opened, 9);  // 7 valid cases and the 2 bad omero blocks
  EXPECT_EQ(refused, 24);
}

TEST(ZarrSpecExamples, ZarrV3CoreArrayExampleParsesToItsShapeChunksTypeAndFill) {
  const std::string name = "array-float64.json";
  const ZarrArrayMeta m = parseZarrJsonArray(readText(examples() / "zarr-v3" / name), name);
  EXPECT_EQ(m.format, 3);
  EXPECT_EQ(m.shape, (std::vector<std::int64_t>{10000, 1000}));
  EXPECT_EQ(m.chunks, (std::vector<std::int64_t>{1000, 100}));
  EXPECT_EQ(m.chunkCount(0) * m.chunkCount(1), 100);  // "100 chunks in total"
  EXPECT_EQ(m.kind, 'f');
  EXPECT_EQ(m.itemSize, 8);
  EXPECT_FALSE(m.bigEndian);
  EXPECT_TRUE(m.converted);  // float64 is held as f32
  EXPECT_EQ(m.target, ScalarType::F32);
  EXPECT_TRUE(std::isnan(m.fill));
  EXPECT_FALSE(m.sharded());
  EXPECT_TRUE(m.transpose.empty());
  EXPECT_TRUE(m.bytesCodecs.empty());
  const std::int64_t index[] = {3, 7};
  EXPECT_EQ(m.chunkKey(index), "c/3/7");  // default encoding, separator "/"
}

TEST(ZarrSpecExamples, ZarrV3CoreExtensionDataTypeExampleIsRefusedInOneLine) {
  const std::string name = "array-extension-data-type.json";
  const std::string text = readText(examples() / "zarr-v3" / name);
  // As published, with its trailing comma: not JSON.
  try {
    (void)parseZarrJsonArray(text, name);
    ADD_FAILURE() << "a trailing comma was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(name + ": ", 0), 0u) << what;
    EXPECT_NE(what.find("JSON"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  // Without it: the made-up extension data type is named and refused.
  try {
    (void)parseZarrJsonArray(withoutTrailingCommas(text), name);
    ADD_FAILURE() << "urn:example:datetime was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(name + ": data_type"), std::string::npos) << what;
    EXPECT_NE(what.find("urn:example:datetime"), std::string::npos) << what;
    EXPECT_NE(what.find("is not supported"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(ZarrSpecExamples, ZarrV3CoreGroupExampleIsAGroupWithoutAnImage) {
  const auto m = std::make_shared<MemoryStorage>("mem://example.ome.zarr");
  m->put("zarr.json", bytesOf(readText(examples() / "zarr-v3/group.json")));
  const std::string error = openError(m);
  EXPECT_NE(error.find("mem://example.ome.zarr/zarr.json: a Zarr v3 group without OME-NGFF "
                       "multiscales"),
            std::string::npos)
      << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

// The sharding codec's example configuration (32x32 inner chunks, bytes
// little-endian + gzip level 1, index bytes + crc32c at the end) on a
// 2x2-shard 128x128 uint16 array.
TEST(ZarrSpecExamples, ShardingCodecExampleParsesToItsInnerChunksCodecsAndIndex) {
  const json codecs = json::parse(
      withoutTrailingCommas(readText(examples() / "zarr-v3/sharding-codecs.json")))["codecs"];
  const json array = {
      {"zarr_format", 3},
      {"node_type", "array"},
      {"shape", {128, 128}},
      {"data_type", "uint16"},
      {"chunk_grid", {{"name", "regular"}, {"configuration", {{"chunk_shape", {64, 64}}}}}},
      {"chunk_key_encoding", {{"name", "default"}}},
      {"fill_value", 0},
      {"codecs", codecs}};
  const ZarrArrayMeta m = parseZarrJsonArray(array.dump(), "sharded");
  ASSERT_TRUE(m.sharded());
  EXPECT_EQ(m.shard, (std::vector<std::int64_t>{64, 64}));
  EXPECT_EQ(m.chunks, (std::vector<std::int64_t>{32, 32}));
  EXPECT_EQ(m.bytesCodecs, std::vector<ZarrBytesCodec>{ZarrBytesCodec::Gzip});
  EXPECT_TRUE(m.indexAtEnd);
  EXPECT_TRUE(m.indexCrc32c);
  EXPECT_EQ(m.chunksPerShard(), 4u);
  EXPECT_EQ(m.shardIndexBytes(), 4u * 16u + 4u);  // the spec's 2x2 index layout
  const std::int64_t inner[] = {3, 1};            // shard (1, 0), inner chunk (1, 1)
  EXPECT_EQ(m.chunkKey(inner), "c/1/0");
  EXPECT_EQ(m.innerChunkIndex(inner), 3u);
}

}  // namespace
}  // namespace tessera
