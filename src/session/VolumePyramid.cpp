#include "tessera/session/VolumePyramid.h"

#include <sstream>

#include "tessera/core/Error.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrStore.h"
#include "tessera/lod/InCoreMultiresSource.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/lod/ZarrMultiresSource.h"

namespace tessera::session {

std::optional<std::vector<std::byte>> CountingStorage::get(const std::string& key,
                                                           std::uint64_t maxBytes) const {
  auto bytes = inner_->get(key, maxBytes);
  const std::size_t slash = key.find_last_of('/');
  const std::string leaf = slash == std::string::npos ? key : key.substr(slash + 1);
  if (!leaf.empty() && leaf.front() != '.') {
    ++chunks_;
    if (bytes) bytes_ += bytes->size();
  }
  return bytes;
}

std::optional<ZarrRange> CountingStorage::getRange(const std::string& key, std::int64_t offset,
                                                   std::uint64_t length,
                                                   std::uint64_t maxWhole) const {
  auto r = inner_->getRange(key, offset, length, maxWhole);
  ++chunks_;
  if (r) bytes_ += r->bytes.size();
  return r;
}

VolumePyramid openVolumePyramid(const std::string& spec, const PyramidOptions& options) {
  if (lod::ProceduralMultiresSource::isSpec(spec)) {
    return {std::make_shared<lod::ProceduralMultiresSource>(spec), nullptr};
  }
  if (isZarrStore(spec)) {
    auto counting = std::make_shared<CountingStorage>(openZarrStorage(spec));
    auto store = std::make_shared<const ZarrStore>(
        counting, ZarrSelection{.time = options.time, .channel = options.channel});
    counting->reset();  // metadata is not what the box costs
    return {std::make_shared<lod::ZarrMultiresSource>(std::move(store)), counting};
  }
  auto volume = std::make_shared<const Volume>(readVolume(
      spec, {.dicomSeries = options.series, .time = options.time, .channel = options.channel}));
  return {std::make_shared<lod::InCoreMultiresSource>(std::move(volume)), nullptr};
}

int parseLevel(const std::string& text, int levelCount, const std::string& spec) {
  if (text == "native") return 0;
  int level = -1;
  std::istringstream in(text);
  if (!(in >> level) || !in.eof() || level < 0 || level >= levelCount) {
    throw InputError("--level '" + text + "': " + spec + " has levels 0.." +
                     std::to_string(levelCount - 1) + " (native = 0, the finest)");
  }
  return level;
}

lod::VoxelBox parseRegion(const std::string& text, glm::ivec3 dims, std::string* clampedNote) {
  lod::VoxelBox box;
  std::istringstream in(text);
  char c[5] = {};
  if (!(in >> box.begin.x >> c[0] >> box.end.x >> c[1] >> box.begin.y >> c[2] >> box.end.y >>
        c[3] >> box.begin.z >> c[4] >> box.end.z) ||
      c[0] != ':' || c[2] != ':' || c[4] != ':' || c[1] != ',' || c[3] != ',' || !in.eof()) {
    throw InputError("--region '" + text +
                     "': expected x0:x1,y0:y1,z0:z1 (voxels of the level, end exclusive)");
  }
  const char* names = "xyz";
  std::string note;
  for (int a = 0; a < 3; ++a) {
    if (box.begin[a] < 0 || box.begin[a] >= dims[a] || box.end[a] <= box.begin[a]) {
      throw InputError("--region '" + text + "': " + names[a] + " range " +
                       std::to_string(box.begin[a]) + ":" + std::to_string(box.end[a]) +
                       " is empty or starts outside 0:" + std::to_string(dims[a]));
    }
    if (box.end[a] > dims[a]) {
      note += std::string(note.empty() ? "" : ", ") + names[a] + " end " +
              std::to_string(box.end[a]) + " clamped to " + std::to_string(dims[a]);
      box.end[a] = dims[a];
    }
  }
  if (clampedNote) *clampedNote = note;
  return box;
}

std::uint64_t chunksTouched(const lod::VoxelBox& box, glm::ivec3 chunk, glm::ivec3 dims) {
  std::uint64_t n = 1;
  for (int a = 0; a < 3; ++a) {
    const int c = chunk[a] > 0 ? chunk[a] : dims[a];
    n *= std::uint64_t((box.end[a] - 1) / c - box.begin[a] / c + 1);
  }
  return n;
}

}  // namespace tessera::session
