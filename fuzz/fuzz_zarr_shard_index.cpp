// libFuzzer target: a sharding_indexed shard index. The input's first two
// bytes choose the layout (inner chunks per shard axis 1..8 each, index at
// the start or end, with or without its crc32c), the next 8 the shard's
// size, the rest is the index: parseShardIndex must accept it only with
// every entry inside the shard, outside the index and not overlapping, or
// throw InputError; never read past the index or allocate by an entry.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "FuzzTarget.h"
#include "tessera/core/Error.h"
#include "tessera/io/ZarrArray.h"

void tessera::fuzz::fuzzOne(const std::uint8_t* data, std::size_t size) {
  if (size < 10) return;
  ZarrArrayMeta m;
  m.format = 3;
  m.dtype = "uint16";
  m.kind = 'u';
  m.itemSize = 2;
  m.target = ScalarType::U16;
  const int per[3] = {1 + (data[0] & 7), 1 + ((data[0] >> 3) & 7), 1 + (data[1] & 7)};
  m.chunks = {4, 4, 4};
  m.shape = {4 * per[0], 4 * per[1], 4 * per[2]};
  m.shard = {4 * per[0], 4 * per[1], 4 * per[2]};
  m.indexAtEnd = (data[1] & 8) != 0;
  m.indexCrc32c = (data[1] & 16) != 0;
  std::uint64_t shardBytes = 0;
  std::memcpy(&shardBytes, data + 2, 8);
  const std::span<const std::byte> index(reinterpret_cast<const std::byte*>(data + 10), size - 10);
  try {
    const auto entries = parseShardIndex(m, index, shardBytes, "fuzz shard");
    // Accepted: every present entry lies in the shard, none overlap.
    for (const ZarrShardEntry& e : entries) {
      if (e.missing()) continue;
      if (e.offset + e.bytes > shardBytes || e.bytes > m.maxStoredChunkBytes()) __builtin_trap();
    }
  } catch (const InputError&) {
  }
}
