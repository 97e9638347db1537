#pragma once
// An OME-Zarr multiscale image (OME-NGFF 0.4 on Zarr v2, 0.5 on Zarr v3:
// the group's zarr.json with the metadata under attributes.ome, sharded
// arrays read one inner chunk at a time), read one box at a time through a
// ZarrStorage (folder, memory or HTTP).
//
// World frame: NGFF axes carry no patient orientation. Tessera maps the
// array's x, y, z space axes to index axes i, j, k and assigns the RAS+
// frame to them (i -> Right, j -> Anterior, k -> Superior), so world =
// scale * index + translation with direction = identity, in the axes' unit
// converted to mm. A store Tessera wrote may add "tessera": {"direction"}
// to its attributes, restoring the direction of the volume it came from;
// with "translations": "array axes" (every store written since) the
// levels' translations are NGFF's own (the half-voxel shift of a coarser
// level in the array's axes) and the direction is applied to them here.
// `info` prints this as the geometry source.
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/io/ZarrArray.h"
#include "tessera/io/ZarrChunkCache.h"
#include "tessera/io/ZarrStorage.h"

namespace tessera {

// Which 3D volume of a 4D/5D (t, c, z, y, x) image to read.
struct ZarrSelection {
  int time = 0;
  int channel = 0;
};

// One channel's OMERO rendering metadata (omero.channels[c]): what a
// viewer shows it with by default.
struct ZarrChannel {
  std::string label;
  glm::vec3 color{1.0f};  // "RRGGBB" as 0..1
  bool active = true;
  bool hasWindow = false;
  ValueRange window{0.0, 0.0};  // start, end
  ValueRange range{0.0, 0.0};   // min, max
};

struct ZarrLevel {
  std::string path;  // the dataset's path in the group ("0", "s1", ...)
  ZarrArrayMeta array;
  glm::ivec3 dims{0};   // x, y, z voxels
  glm::ivec3 chunk{0};  // x, y, z chunk voxels
  glm::dvec3 spacing{1.0};
  glm::dvec3 origin{0.0};  // world position of voxel (0,0,0)'s centre
};

class ZarrStore {
 public:
  // Reads the group's metadata (.zattrs multiscales; or a lone .zarray at
  // the root as a one-level store) and every level's .zarray; checks the
  // selection and every level against the host budget. InputError naming
  // the key's path or URL.
  explicit ZarrStore(std::shared_ptr<const ZarrStorage> storage, ZarrSelection selection = {});

  // Keeps decoded chunks up to `bytes` from now on (io/ZarrChunkCache.h;
  // the default 0 keeps none, though a chunk being decoded is still shared
  // between readers): what a reader of many small boxes (bricks) needs; a
  // reader of whole levels does not.
  void keepDecodedChunks(std::uint64_t bytes) { chunks_ = std::make_shared<ZarrChunkCache>(bytes); }
  // The decoded chunks' budget changed on the cache already kept (the
  // bricks layout's share of the host budget), chunks over it let go.
  void limitDecodedChunks(std::uint64_t bytes) const { chunks_->setBudget(bytes); }

  // The finest level's dims, type and geometry with the value window of
  // the store (from its metadata or its coarsest level); no voxels.
  const Volume& shape() const { return shape_; }
  int levelCount() const { return static_cast<int>(levels_.size()); }
  const ZarrLevel& level(int l) const;

  // Called after each chunk of a readBox with (chunks done, chunks in the
  // box), from one thread at a time.
  using Progress = std::function<void(std::size_t done, std::size_t total)>;

  // Voxels [begin, end) of level `l` (x, y, z) as a Volume of end - begin
  // voxels, geometry = the level's spacing, origin at `begin`. Reads only
  // the chunks the box touches, `parallelism()` at a time. Thread-safe.
  // InputError naming the chunk's path or URL for a corrupt chunk; a
  // missing chunk is fill_value.
  Volume readBox(int l, glm::ivec3 begin, glm::ivec3 end, const Progress& progress = {}) const;
  Volume readLevel(int l, const Progress& progress = {}) const {
    return readBox(l, glm::ivec3(0), level(l).dims, progress);
  }

  // The storage keys of the chunks readBox(l, begin, end) reads, in its
  // order: what an asynchronous storage (the browser's fetch()) must hold
  // before the read.
  std::vector<std::string> chunkKeys(int l, glm::ivec3 begin, glm::ivec3 end) const;
  // Whether the storage holds every read readBox(l, begin, end) makes,
  // `holds` asked about each in readBox's order (an asynchronous storage
  // notes those it lacks as wanted, and the caller asks again once they
  // arrived). Unsharded: each chunk's key. Sharded: each shard's index
  // (asked only until this store has read it) and, once it is held, the
  // byte ranges of the inner chunks the box touches; inner chunks the
  // index marks absent (fill_value) and absent shards need no read. A
  // corrupt index: InputError as readBox.
  bool holdsReads(int l, glm::ivec3 begin, glm::ivec3 end,
                  const std::function<bool(const ZarrStoredRead&)>& holds) const;

  // The finest level whose voxels (plus one chunk per reader) fit the host
  // budget; -1 if none does.
  int finestLevelWithin(std::uint64_t budgetBytes) const;
  // finestLevelWithin(the global host budget), or a BudgetError naming
  // `spec` and the coarsest level when none fits.
  int finestLevelInHostBudget(const std::string& spec) const;

  // Things the user should know ("dtype <i4 is read as f32", "axes have no
  // unit: taken as mm").
  const std::vector<std::string>& notes() const { return notes_; }
  // The omero channels, in the store's channel order (empty without omero).
  const std::vector<ZarrChannel>& channels() const { return channels_; }
  // The length of the store's t axis (1 without one): its time points.
  int timePoints() const;
  // The length of the store's c axis (1 without one).
  int channelCount() const;
  // 2 or 3: the store's Zarr format.
  int zarrFormat() const { return format_; }
  // The multiscales "type": how the coarser levels were made ("mean",
  // "gaussian", "nearest", ...; "" when the metadata does not say).
  const std::string& reduction() const { return reduction_; }
  // "OME-NGFF 0.4 (multiscales 'name'), 3 levels, blosc lz4 shuffle".
  std::string describe() const;
  const ZarrStorage& storage() const { return *storage_; }
  // The same storage, shared: another selection of the store (a time point
  // played after this one) reads its keys without opening it again.
  std::shared_ptr<const ZarrStorage> sharedStorage() const { return storage_; }
  const ZarrSelection& selection() const { return selection_; }
  // Chunks decoded, found decoded, waited for; bytes held.
  ZarrChunkCacheStats chunkStats() const { return chunks_->stats(); }
  std::uint64_t chunkCacheBytes() const { return chunks_->budgetBytes(); }
  // The decoded bytes of every chunk of every level: the most that reading
  // the whole store (every brick of every level) holds in the chunk cache.
  std::uint64_t allChunkBytes() const;

 private:
  struct AxisMap;
  bool readV3Root(const std::string& body);
  ZarrArrayMeta readArrayMeta(const std::string& path) const;
  void readMultiscales();
  void readChannels();
  void readLoneArray();
  void addLevel(const std::string& path, glm::dvec3 scale, glm::dvec3 translation);
  void checkSelection();
  void makeShape();
  std::vector<std::int64_t> chunkIndexAt(int l, const std::vector<std::int64_t>& spatial) const;
  std::string chunkKeyAt(int l, const std::vector<std::int64_t>& spatial) const;
  struct ShardIndex;
  // A shard's checked index, read once (nullptr: the shard is absent).
  std::shared_ptr<const ShardIndex> shardIndex(const ZarrArrayMeta& m,
                                               const std::string& key) const;
  void readChunkInto(int l, const std::vector<std::int64_t>& chunkIndex, glm::ivec3 begin,
                     glm::ivec3 end, Volume& out) const;
  // `inner` < 0: the chunk stored under `key`; else that inner chunk of
  // the shard stored under `key`.
  ZarrChunkCache::Chunk decodeChunk(const ZarrArrayMeta& m, const std::string& key,
                                    std::int64_t inner) const;

  std::shared_ptr<const ZarrStorage> storage_;
  ZarrSelection selection_;
  std::shared_ptr<ZarrChunkCache> chunks_;
  int format_ = 2;
  std::string attrsWhere_;  // .zattrs or the group's zarr.json
  std::string attrsText_;   // the attributes (Tessera's own "tessera" among them)
  std::string ngffText_;    // what holds multiscales and omero (v3: attributes.ome)
  std::vector<ZarrChannel> channels_;
  mutable std::mutex shardMutex_;
  mutable std::map<std::string, std::shared_future<std::shared_ptr<const ShardIndex>>> shards_;
  std::string version_;
  std::string name_;
  std::string reduction_;
  // Array axis of x, y, z, t, c (-1: the array has no such axis).
  int axis_[5] = {-1, -1, -1, -1, -1};
  double unitToMm_ = 1.0;
  glm::dmat3 direction_{1.0};
  std::vector<ZarrLevel> levels_;
  Volume shape_;
  std::vector<std::string> notes_;
};

// True when `spec` is an http:// or https:// URL (other than a DICOMweb
// series URL, io/DicomWeb.h), or a folder holding .zgroup, .zattrs,
// .zarray or zarr.json.
bool isZarrStore(const std::string& spec);

// The storage for a folder or a URL.
std::shared_ptr<const ZarrStorage> openZarrStorage(const std::string& spec);

// The finest level of the store that fits the host budget, read in-core;
// `chosenNote` (if given) says which level and why.
Volume readZarrVolume(const std::string& spec, ZarrSelection selection = {},
                      std::string* chosenNote = nullptr);

}  // namespace tessera
