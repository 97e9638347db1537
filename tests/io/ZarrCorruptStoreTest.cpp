// Corrupt OME-Zarr stores: every one is refused with an InputError or a
// BudgetError naming the file (or chunk) and the problem, before anything
// the declared sizes cannot justify is allocated.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "io/ZarrTestSupport.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/io/ZarrWriter.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

void put(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary | std::ios::trunc) << text;
}

const char* kAttrs = R"({"multiscales": [{"version": "0.4",
  "axes": [{"name": "z", "type": "space"}, {"name": "y", "type": "space"},
           {"name": "x", "type": "space"}],
  "datasets": [{"path": "0", "coordinateTransformations":
                [{"type": "scale", "scale": [1, 1, 1]}]}]}]})";

std::string zarray(const std::string& shape, const std::string& chunks,
                   const std::string& dtype = "\"|u1\"", const std::string& extra = "") {
  return R"({"zarr_format": 2, "shape": )" + shape + R"(, "chunks": )" + chunks + R"(, "dtype": )" +
         dtype + R"(, "order": "C", "fill_value": 0, "filters": null,
         "compressor": null)" +
         extra + "}";
}

// A one-level store with the given .zarray.
fs::path store(const TempDir& tmp, const std::string& arrayJson) {
  const fs::path root = tmp / "s.ome.zarr";
  put(root / ".zgroup", R"({"zarr_format": 2})");
  put(root / ".zattrs", kAttrs);
  put(root / "0" / ".zarray", arrayJson);
  return root;
}

// readVolume's error, which must be of type E and contain every `parts`.
template <class E>
void expectRefused(const fs::path& root, std::initializer_list<std::string> parts) {
  try {
    readVolume(root.string());
    FAIL() << root << " was read";
  } catch (const E& e) {
    const std::string m = e.what();
    for (const std::string& p : parts) EXPECT_NE(m.find(p), std::string::npos) << m;
  } catch (const std::exception& e) {
    FAIL() << "wrong error type: " << e.what();
  }
}

TEST(ZarrCorruptStore, BadJsonNamesTheFile) {
  const TempDir tmp;
  const fs::path root = store(tmp, "{\"zarr_format\": 2, \"shape\": [");
  expectRefused<InputError>(root, {"0/.zarray", "not valid JSON"});
  put(root / ".zattrs", "{\"multiscales\": [}");
  expectRefused<InputError>(root, {".zattrs", "not valid JSON"});
}

TEST(ZarrCorruptStore, ShapeTimesDtypeBeyondTheBudgetIsRefusedBeforeAllocating) {
  const TempDir tmp;
  const test::BudgetOverride budget(64ull << 20);
  expectRefused<BudgetError>(store(tmp, zarray("[4096, 4096, 4096]", "[64, 64, 64]", "\"<u2\"")),
                             {"s.ome.zarr", "4096x4096x4096", "host budget"});
  expectRefused<BudgetError>(
      store(tmp, zarray("[4096, 4096, 4096]", "[4096, 4096, 4096]", "\"<f8\"")),
      {"0/.zarray", "one chunk"});
  expectRefused<BudgetError>(
      store(tmp, zarray("[2, 2, 2]", "[1099511627776, 1099511627776, 1099511627776]")),
      {"0/.zarray", "larger than any host"});
}

TEST(ZarrCorruptStore, ZeroNegativeOrFractionalChunksAreRefused) {
  const TempDir tmp;
  expectRefused<InputError>(store(tmp, zarray("[10, 10, 10]", "[0, 5, 5]")),
                            {"0/.zarray", "chunks", "positive integer"});
  expectRefused<InputError>(store(tmp, zarray("[10, 10, 10]", "[-4, 5, 5]")),
                            {"0/.zarray", "positive integer"});
  expectRefused<InputError>(store(tmp, zarray("[10, -10, 10]", "[5, 5, 5]")),
                            {"0/.zarray", "shape"});
  expectRefused<InputError>(store(tmp, zarray("[10, 10, 10]", "[5.5, 5, 5]")),
                            {"0/.zarray", "positive integer"});
  expectRefused<InputError>(store(tmp, zarray("[10, 10]", "[5, 5]")), {"0/.zarray", "2 axes"});
}

// fuzz_zarr found these: a field of the wrong JSON type made nlohmann throw a
// type_error that escaped the reader (std::terminate).
TEST(ZarrCorruptStore, FieldsOfTheWrongJsonTypeAreInputErrors) {
  const TempDir tmp;
  expectRefused<InputError>(
      store(tmp, R"({"zarr_format": 2, "shape": [4,5,6], "chunks": [4,5,6], "dtype": "<u2",
        "order": 0, "filters": null, "compressor": {"id": "zlib", "level": 1}})"),
      {"0/.zarray", "wrong type"});
  expectRefused<InputError>(
      store(tmp, R"({"zarr_format": 2, "shape": "big", "chunks": [4,4,4], "dtype": "|u1",
        "order": "C", "fill_value": 0, "compressor": null})"),
      {"0/.zarray"});
  const fs::path root = store(tmp, zarray("[4, 4, 4]", "[4, 4, 4]"));
  put(root / ".zattrs", R"({"multiscales": [{"version": "0.4", "axes": 7, "datasets": 3}]})");
  expectRefused<InputError>(root, {"s.ome.zarr"});
}

TEST(ZarrCorruptStore, UnsupportedLayoutsSayWhat) {
  const TempDir tmp;
  expectRefused<InputError>(
      store(tmp, R"({"zarr_format": 2, "shape": [4,4,4], "chunks": [4,4,4], "dtype": "|u1",
        "order": "F", "fill_value": 0, "compressor": null})"),
      {"0/.zarray", "order \"F\""});
  expectRefused<InputError>(store(tmp, zarray("[4, 4, 4]", "[4, 4, 4]", "\"<c8\"")),
                            {"0/.zarray", "<c8", "not supported"});
  expectRefused<InputError>(
      store(tmp, R"({"zarr_format": 2, "shape": [4,4,4], "chunks": [4,4,4], "dtype": "|u1",
        "order": "C", "fill_value": 0, "compressor": {"id": "lzma"}})"),
      {"0/.zarray", "lzma", "not supported"});
  expectRefused<InputError>(
      store(tmp, zarray("[4, 4, 4]", "[4, 4, 4]", "\"|u1\"", R"(, "dimension_separator": "-")")),
      {"0/.zarray", "dimension_separator"});
  const fs::path root = store(tmp, zarray("[4, 4, 4]", "[4, 4, 4]"));
  fs::remove(root / "0" / ".zarray");
  expectRefused<InputError>(root, {"0/.zarray", "missing"});
}

// A valid store of `compressor` whose chunk 0/0/0/0 is then damaged.
fs::path writtenStore(const TempDir& tmp, ZarrCompressor compressor) {
  const Volume v = test::randomVolume({20, 20, 20}, ScalarType::U16, 3);
  OmeZarrWriteOptions o;
  o.chunk = 16;
  o.levels = 1;
  o.compressor = compressor;
  const fs::path root = tmp / "w.ome.zarr";
  writeOmeZarr(v, root, o);
  return root;
}

TEST(ZarrCorruptStore, TruncatedCompressedChunkNamesTheChunk) {
  for (ZarrCompressor c :
       {ZarrCompressor::Zstd, ZarrCompressor::Blosc, ZarrCompressor::Zlib, ZarrCompressor::None}) {
    SCOPED_TRACE(int(c));
    const TempDir tmp;
    const fs::path root = writtenStore(tmp, c);
    const fs::path chunk = root / "0" / "0" / "0" / "0";
    fs::resize_file(chunk, fs::file_size(chunk) / 2);
    expectRefused<InputError>(root, {chunk.string()});
  }
}

TEST(ZarrCorruptStore, WrongDecompressedSizeNamesTheChunk) {
  for (ZarrCompressor c : {ZarrCompressor::Zstd, ZarrCompressor::Blosc, ZarrCompressor::Zlib}) {
    SCOPED_TRACE(int(c));
    const TempDir tmp;
    const fs::path root = writtenStore(tmp, c);
    const fs::path chunk = root / "0" / "0" / "1" / "0";
    // A well-formed stream of 1000 bytes where 16^3 u16 (8192) belong.
    const std::vector<std::byte> small(1000, std::byte{7});
    const std::vector<std::byte> stored = encodeZarrChunk(c, 2, small);
    std::ofstream(chunk, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(stored.data()), std::streamsize(stored.size()));
    expectRefused<InputError>(root, {chunk.string(), "8192"});
  }
}

TEST(ZarrCorruptStore, GarbageChunkAndOversizedChunkAreErrorsNotCrashes) {
  const TempDir tmp;
  const fs::path root = writtenStore(tmp, ZarrCompressor::Blosc);
  const fs::path chunk = root / "0" / "1" / "0" / "1";
  std::string garbage(300, '\0');
  for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = char(i * 37 + 11);
  put(chunk, garbage);
  expectRefused<InputError>(root, {chunk.string()});
  put(chunk, std::string(100000, 'x'));
  expectRefused<InputError>(root, {chunk.string(), "more than"});
}

}  // namespace
}  // namespace tessera
