#pragma once
// Any volume argument as a lod::MultiresSource, so that `slice` and
// `render --region` read one box of one level and never a whole level of a
// store: an OME-Zarr store (folder or URL) through its chunks, head:WxHxD
// brick by brick, any other file read in core (its pyramid downsampled).
// Stores are read through a storage that counts the chunks and bytes it
// fetches, so the commands can report what a bounded read cost.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "tessera/io/ZarrStorage.h"
#include "tessera/lod/MultiresSource.h"

namespace tessera::session {

// A ZarrStorage that forwards to another and counts chunk fetches (keys
// whose last part is not metadata such as .zarray) and their bytes.
class CountingStorage final : public ZarrStorage {
 public:
  explicit CountingStorage(std::shared_ptr<const ZarrStorage> inner) : inner_(std::move(inner)) {}
  std::optional<std::vector<std::byte>> get(const std::string& key,
                                            std::uint64_t maxBytes) const override;
  // A sharded store's reads (an index, an inner chunk): counted as chunks.
  std::optional<ZarrRange> getRange(const std::string& key, std::int64_t offset,
                                    std::uint64_t length, std::uint64_t maxWhole) const override;
  std::string locate(const std::string& key) const override { return inner_->locate(key); }
  int refetches() const override { return inner_->refetches(); }
  int parallelism() const override { return inner_->parallelism(); }
  std::string describe() const override { return inner_->describe(); }

  std::uint64_t chunksRead() const { return chunks_.load(); }
  std::uint64_t chunkBytesRead() const { return bytes_.load(); }
  void reset() {
    chunks_ = 0;
    bytes_ = 0;
  }

 private:
  std::shared_ptr<const ZarrStorage> inner_;
  mutable std::atomic<std::uint64_t> chunks_{0};
  mutable std::atomic<std::uint64_t> bytes_{0};
};

struct VolumePyramid {
  std::shared_ptr<const lod::MultiresSource> source;
  std::shared_ptr<CountingStorage> storage;  // stores only: what readBox fetched
};

struct PyramidOptions {
  std::string series;  // DICOM Series Instance UID
  int time = 0;        // OME-Zarr time point and channel
  int channel = 0;
};

VolumePyramid openVolumePyramid(const std::string& spec, const PyramidOptions& options);

// --level: "native" (= 0) or a level number below `levelCount`; InputError
// naming the option and the levels there are.
int parseLevel(const std::string& text, int levelCount, const std::string& spec);

// x0:x1,y0:y1,z0:z1 (voxels, end exclusive) in a level of `dims`. An end
// past the level is clamped to it (and `clampedNote` says so); an empty
// range or a start outside the level is an InputError naming the axis.
lod::VoxelBox parseRegion(const std::string& text, glm::ivec3 dims, std::string* clampedNote);

// Chunks of `chunk` voxels (0: the whole level is one) that `box` touches.
std::uint64_t chunksTouched(const lod::VoxelBox& box, glm::ivec3 chunk, glm::ivec3 dims);

}  // namespace tessera::session
