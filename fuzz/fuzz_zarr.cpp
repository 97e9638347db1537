// libFuzzer target: an OME-Zarr array's .zarray and one stored chunk. The
// input is the .zarray text, a NUL byte, then the chunk's bytes (stored
// under key 0/0.0.0 of a one-level NGFF 0.4 store in memory); the store is
// opened and its first chunk's box read, which runs parseZarray,
// decodeZarrChunk (zlib, gzip, zstd, blosc or none) and the box assembly.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "FuzzTarget.h"
#include "tessera/io/ZarrStore.h"

namespace {
const char* kAttrs =
    R"({"multiscales": [{"version": "0.4", "axes": [{"name": "z", "type": "space"},)"
    R"({"name": "y", "type": "space"}, {"name": "x", "type": "space"}],)"
    R"("datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale",)"
    R"("scale": [1, 1, 1]}]}]}], "tessera": {"value_range": [0, 1]}})";

std::vector<std::byte> bytes(const std::uint8_t* p, std::size_t n) {
  const auto* b = reinterpret_cast<const std::byte*>(p);
  return {b, b + n};
}
}  // namespace

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  const std::uint8_t* nul = std::find(data, data + size, std::uint8_t{0});
  auto storage = std::make_shared<MemoryStorage>("input.zarr");
  const std::string attrs(kAttrs);
  storage->put(".zattrs", bytes(reinterpret_cast<const std::uint8_t*>(attrs.data()), attrs.size()));
  storage->put("0/.zarray", bytes(data, std::size_t(nul - data)));
  if (nul != data + size) {
    const std::vector<std::byte> chunk = bytes(nul + 1, std::size_t(data + size - nul - 1));
    storage->put("0/0.0.0", chunk);
    storage->put("0/0/0/0", chunk);
  }
  const ZarrStore store(storage);
  const ZarrLevel& l = store.level(0);
  store.readBox(0, glm::ivec3(0), glm::min(l.dims, l.chunk));
}
