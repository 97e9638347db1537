#include "tessera/io/ZarrWriter.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/VolumeWriter.h"
#include "tessera/io/ZarrStore.h"

namespace tessera {

namespace fs = std::filesystem;

namespace {

void writeBytes(const fs::path& path, const void* data, std::size_t n) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(n));
  out.close();
  if (!out) throw Error(path.string() + ": cannot write");
}

void writeText(const fs::path& path, const std::string& s) {
  writeBytes(path, s.data(), s.size());
}

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// Slices [0, depth) of `src` reduced by `f` per axis into a new volume of
// ceil(dims/f) (depth for z): the mean of the voxels present, NaN skipped,
// as lod::downsample(src, f).
Volume reduce(const Volume& src, int depth, glm::ivec3 f) {
  const glm::ivec3 d(src.dims().x, src.dims().y, depth);
  const glm::ivec3 o = (d + f - 1) / f;
  Volume out = Volume::allocate(o, src.type(), "pyramid slab");
  for (int oz = 0; oz < o.z; ++oz) {
    for (int oy = 0; oy < o.y; ++oy) {
      for (int ox = 0; ox < o.x; ++ox) {
        double sum = 0.0;
        int n = 0;
        for (int z = f.z * oz; z < std::min(d.z, f.z * oz + f.z); ++z) {
          for (int y = f.y * oy; y < std::min(d.y, f.y * oy + f.y); ++y) {
            for (int x = f.x * ox; x < std::min(d.x, f.x * ox + f.x); ++x) {
              const double v = src.valueAt(x, y, z);
              if (std::isfinite(v)) {
                sum += v;
                ++n;
              }
            }
          }
        }
        out.setValueAtIndex(out.index(ox, oy, oz),
                            n ? sum / n : std::numeric_limits<double>::quiet_NaN());
      }
    }
  }
  return out;
}

// "2x2x2", "1x2x2": the factors as text in NGFF's axis order (z by y by x).
std::string factorsText(glm::ivec3 f) {
  return dimsText({f.z, f.y, f.x});
}

// One level of the pyramid being written: a slab of chunk.z slices that
// fills up, is cut into chunks, and is reduced into the next level.
// A shard being appended to: the index entries of its inner chunks so far.
struct OpenShard {
  std::vector<ZarrShardEntry> entries;
  std::uint64_t bytes = 0;
};

struct LevelWriter {
  int index = 0;
  glm::ivec3 dims{0};
  glm::ivec3 chunk{0};
  glm::ivec3 shard{0};                             // inner chunks per shard per axis (0: unsharded)
  std::map<std::array<int, 3>, OpenShard> shards;  // by shard (x, y, z)
  fs::path dir;
  Volume slab;  // dims.x x dims.y x chunk.z
  int slabZ0 = 0;
  int filled = 0;
};

class PyramidWriter {
 public:
  PyramidWriter(const Volume& shape, const fs::path& root, const OmeZarrWriteOptions& o)
      : type_(shape.type()), root_(root), options_(o) {
    glm::ivec3 d = shape.dims();
    const int count = o.levels > 0 ? o.levels : omeZarrAutoLevels(d, o.chunkXyz(), o.factors);
    for (int l = 0; l < count; ++l) {
      LevelWriter w;
      w.index = l;
      w.dims = d;
      w.chunk = glm::min(d, o.chunkXyz());
      if (o.zarrFormat == 3 && o.shard > 0) {
        w.shard = glm::min(glm::ivec3(o.shard), (d + w.chunk - 1) / w.chunk);
      }
      w.dir = root / std::to_string(l);
      w.slab = Volume::allocate({d.x, d.y, w.chunk.z}, type_,
                                "OME-Zarr level " + std::to_string(l) + " slab");
      levels_.push_back(std::move(w));
      const glm::ivec3 next = (d + o.factors - 1) / o.factors;
      if (next == d) break;  // every reduced axis is down to one voxel
      d = next;
    }
  }

  int levelCount() const { return static_cast<int>(levels_.size()); }
  const LevelWriter& level(int l) const { return levels_[std::size_t(l)]; }
  OmeZarrWriteResult result() {
    result_.chunksWritten = written_;
    result_.chunksSkipped = skipped_;
    result_.bytesWritten = bytes_;
    return result_;
  }
  static OmeZarrWriteResult emptyResult() {
    OmeZarrWriteResult r;
    r.range = {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    return r;
  }

  // Appends the slices of `part` to level l.
  void push(int l, const Volume& part) {
    LevelWriter& w = levels_[std::size_t(l)];
    const std::size_t sliceBytes =
        std::size_t(w.dims.x) * std::size_t(w.dims.y) * bytesPerVoxel(type_);
    for (int z = 0; z < part.dims().z; ++z) {
      std::memcpy(w.slab.bytes().data() + std::size_t(w.filled) * sliceBytes,
                  part.bytes().data() + std::size_t(z) * sliceBytes, sliceBytes);
      ++w.filled;
      if (w.filled == w.chunk.z || w.slabZ0 + w.filled == w.dims.z) flush(l);
    }
    if (l == 0) trackRange(part);
  }

 private:
  void trackRange(const Volume& part) {
    const ValueRange r = part.valueRange();
    result_.range.min = std::min(result_.range.min, r.min);
    result_.range.max = std::max(result_.range.max, r.max);
  }

  void flush(int l) {
    LevelWriter& w = levels_[std::size_t(l)];
    writeChunks(w);
    if (w.shard.x > 0) {
      // The slab that ends a row of shards (or the level) completes them.
      const int cz = w.slabZ0 / w.chunk.z;
      if ((cz + 1) % w.shard.z == 0 || w.slabZ0 + w.filled == w.dims.z)
        closeShards(w, cz / w.shard.z);
    }
    if (l + 1 < levelCount()) push(l + 1, reduce(w.slab, w.filled, options_.factors));
    w.slabZ0 += w.filled;
    w.filled = 0;
  }

  // The chunks of one slab, compressed on a few threads.
  void writeChunks(LevelWriter& w) {
    const int cz = w.slabZ0 / w.chunk.z;
    const int ny = (w.dims.y + w.chunk.y - 1) / w.chunk.y;
    const int nx = (w.dims.x + w.chunk.x - 1) / w.chunk.x;
    const fs::path zdir = w.dir / (options_.zarrFormat == 3 ? "c/" : "") / std::to_string(cz);
    std::atomic<int> next{0};
    std::mutex mutex;
    std::exception_ptr failure;
    auto work = [&] {
      for (int i = next++; i < nx * ny; i = next++) {
        try {
          writeChunk(w, zdir, i % nx, i / nx);
        } catch (...) {
          const std::lock_guard lock(mutex);
          if (!failure) failure = std::current_exception();
        }
      }
    };
    const int threads = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 4u));
    {
      std::vector<std::jthread> pool;
      for (int t = 1; t < std::min(threads, nx * ny); ++t) pool.emplace_back(work);
      work();
    }
    if (failure) std::rethrow_exception(failure);
  }

  void writeChunk(LevelWriter& w, const fs::path& zdir, int cx, int cy) {
    const std::size_t bpv = bytesPerVoxel(type_);
    const glm::ivec3 c = w.chunk;
    std::vector<std::byte> raw(std::size_t(c.x) * std::size_t(c.y) * std::size_t(c.z) * bpv);
    const int x0 = cx * c.x, y0 = cy * c.y;
    const int nx = std::min(c.x, w.dims.x - x0);
    bool zero = true;
    for (int z = 0; z < w.filled; ++z) {
      for (int y = 0; y < std::min(c.y, w.dims.y - y0); ++y) {
        const std::byte* src = w.slab.bytes().data() + w.slab.index(x0, y0 + y, z) * bpv;
        std::byte* dst = raw.data() + ((std::size_t(z) * c.y + y) * c.x) * bpv;
        std::memcpy(dst, src, std::size_t(nx) * bpv);
      }
    }
    for (std::byte b : raw) {
      if (b != std::byte{0}) {
        zero = false;
        break;
      }
    }
    if (zero) {
      // Zarr reads an absent chunk as fill_value (0): nothing to store.
      ++skipped_;
      return;
    }
    const ZarrCompressor codec =
        options_.zarrFormat == 3 && options_.compressor == ZarrCompressor::Zlib
            ? ZarrCompressor::Gzip
            : options_.compressor;
    const std::vector<std::byte> stored = encodeZarrChunk(codec, int(bpv), raw);
    const int cz = w.slabZ0 / c.z;
    if (w.shard.x > 0) {
      appendToShard(w, {cx, cy, cz}, stored);
    } else {
      {
        const std::lock_guard lock(dirMutex_);
        fs::create_directories(zdir / std::to_string(cy));
      }
      writeBytes(zdir / std::to_string(cy) / std::to_string(cx), stored.data(), stored.size());
    }
    bytes_ += stored.size();
    ++written_;
  }

  fs::path shardPath(const LevelWriter& w, const std::array<int, 3>& s) const {
    return w.dir / "c" / std::to_string(s[2]) / std::to_string(s[1]) / std::to_string(s[0]);
  }

  // Appends one inner chunk to its shard's file and records where.
  void appendToShard(LevelWriter& w, glm::ivec3 c, const std::vector<std::byte>& stored) {
    const std::array<int, 3> s = {c.x / w.shard.x, c.y / w.shard.y, c.z / w.shard.z};
    const glm::ivec3 in = c - glm::ivec3(s[0], s[1], s[2]) * w.shard;
    const std::size_t inner =
        (std::size_t(in.z) * std::size_t(w.shard.y) + std::size_t(in.y)) * std::size_t(w.shard.x) +
        std::size_t(in.x);
    const std::lock_guard lock(dirMutex_);
    OpenShard& shard = w.shards[s];
    if (shard.entries.empty()) {
      shard.entries.assign(std::size_t(w.shard.x) * std::size_t(w.shard.y) * std::size_t(w.shard.z),
                           {~std::uint64_t{0}, ~std::uint64_t{0}});
      fs::create_directories(shardPath(w, s).parent_path());
    }
    appendBytes(shardPath(w, s), stored);
    shard.entries[inner] = {shard.bytes, stored.size()};
    shard.bytes += stored.size();
  }

  void closeShards(LevelWriter& w, int sz) {
    for (auto it = w.shards.begin(); it != w.shards.end();) {
      if (it->first[2] != sz) {
        ++it;
        continue;
      }
      appendBytes(shardPath(w, it->first), encodeShardIndex(it->second.entries));
      it = w.shards.erase(it);
    }
  }

  static void appendBytes(const fs::path& path, const std::vector<std::byte>& b) {
    std::ofstream out(path, std::ios::binary | std::ios::app);
    out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
    out.close();
    if (!out) throw Error(path.string() + ": cannot write");
  }

  ScalarType type_;
  fs::path root_;
  OmeZarrWriteOptions options_;
  std::vector<LevelWriter> levels_;
  std::mutex dirMutex_;
  std::atomic<std::uint64_t> written_{0}, skipped_{0}, bytes_{0};
  OmeZarrWriteResult result_ = emptyResult();
};

nlohmann::json zyx(glm::dvec3 v) {
  return {v.z, v.y, v.x};
}

std::string attributes(const Volume& shape, const PyramidWriter& p, const std::string& name,
                       const ValueRange& range, const OmeZarrWriteOptions& o) {
  const int format = o.zarrFormat;
  using nlohmann::json;
  json axes = json::array();
  for (const char* a : {"z", "y", "x"}) {
    axes.push_back({{"name", a}, {"type", "space"}, {"unit", "millimeter"}});
  }
  json datasets = json::array();
  for (int l = 0; l < p.levelCount(); ++l) {
    // Level l's scale per axis: the factor to the power l (1 on a kept axis).
    const glm::dvec3 f(std::pow(double(o.factors.x), l), std::pow(double(o.factors.y), l),
                       std::pow(double(o.factors.z), l));
    const glm::dvec3 spacing = shape.spacing() * f;
    // A level-l voxel is the mean of f finer voxels per axis: its centre
    // lies (f - 1)/2 finest voxels past the first of them (none on a kept
    // axis), in the array's own axes (NGFF has no direction; the reader
    // applies tessera.direction to the shift, "translations": "array axes").
    const glm::dvec3 origin = shape.origin() + shape.spacing() * (0.5 * (f - 1.0));
    datasets.push_back({{"path", std::to_string(l)},
                        {"coordinateTransformations",
                         json::array({{{"type", "scale"}, {"scale", zyx(spacing)}},
                                      {{"type", "translation"}, {"translation", zyx(origin)}}})}});
  }
  json ms = {{"version", "0.4"},
             {"name", name},
             {"axes", axes},
             {"datasets", datasets},
             {"type", "mean"},
             {"metadata",
              {{"method", "tessera convert: " + factorsText(o.factors) +
                              " (z by y by x) mean (lod::downsample), partial edge blocks "
                              "average the voxels present"},
               {"world_frame", "RAS+ millimetres; x->R, y->A, z->S when direction is identity"}}}};
  if (format == 3) ms.erase("version");  // 0.5: the version is the "ome" object's
  json tessera = {{"world_frame", "RAS"}, {"translations", "array axes"}};
  json dir = json::array();
  for (int c = 0; c < 3; ++c) {
    dir.push_back({shape.direction()[c][0], shape.direction()[c][1], shape.direction()[c][2]});
  }
  tessera["direction"] = dir;
  if (range.max >= range.min) tessera["value_range"] = {range.min, range.max};
  if (shape.hasWindow()) tessera["window"] = {shape.window().min, shape.window().max};
  if (format == 3) {
    const json attrs = {{"ome", {{"version", "0.5"}, {"multiscales", json::array({ms})}}},
                        {"tessera", tessera}};
    return json({{"zarr_format", 3}, {"node_type", "group"}, {"attributes", attrs}}).dump(2);
  }
  return json({{"multiscales", json::array({ms})}, {"tessera", tessera}}).dump(2);
}

void build(const Volume& shape, const SlabReader& slabs, const fs::path& root,
           const OmeZarrWriteOptions& o, const std::string& name, OmeZarrWriteResult& result) {
  fs::create_directories(root);
  PyramidWriter pyramid(shape, root, o);
  for (int l = 0; l < pyramid.levelCount(); ++l) {
    const LevelWriter& w = pyramid.level(l);
    fs::create_directories(w.dir);
    if (o.zarrFormat == 3) {
      std::vector<std::int64_t> shard;
      if (w.shard.x > 0) {
        shard = {std::int64_t(w.chunk.z) * w.shard.z, std::int64_t(w.chunk.y) * w.shard.y,
                 std::int64_t(w.chunk.x) * w.shard.x};
      }
      writeText(w.dir / "zarr.json",
                zarrJsonArray({w.dims.z, w.dims.y, w.dims.x}, {w.chunk.z, w.chunk.y, w.chunk.x},
                              shard, shape.type(), o.compressor));
    } else {
      writeText(w.dir / ".zarray",
                zarrayJson({w.dims.z, w.dims.y, w.dims.x}, {w.chunk.z, w.chunk.y, w.chunk.x},
                           shape.type(), o.compressor));
    }
  }
  const glm::ivec3 d = shape.dims();
  const int step = pyramid.level(0).chunk.z;
  for (int z0 = 0; z0 < d.z; z0 += step) {
    const int z1 = std::min(d.z, z0 + step);
    const Volume part = slabs(z0, z1);
    if (part.dims() != glm::ivec3(d.x, d.y, z1 - z0) || part.type() != shape.type()) {
      throw Error("OME-Zarr writer: slab " + std::to_string(z0) + ".." + std::to_string(z1) +
                  " is " + dimsText(part.dims()) + ", expected " + dimsText({d.x, d.y, z1 - z0}));
    }
    pyramid.push(0, part);
    if (o.progress) {
      o.progress(double(z1) / d.z, "slices " + std::to_string(z1) + "/" + std::to_string(d.z));
    }
  }
  result = pyramid.result();
  if (o.zarrFormat == 3) {
    writeText(root / "zarr.json", attributes(shape, pyramid, name, result.range, o));
  } else {
    writeText(root / ".zgroup", "{\n  \"zarr_format\": 2\n}");
    writeText(root / ".zattrs", attributes(shape, pyramid, name, result.range, o));
  }
  for (int l = 0; l < pyramid.levelCount(); ++l) result.levelDims.push_back(pyramid.level(l).dims);
}

}  // namespace

bool isOmeZarrName(const fs::path& path) {
  std::string s = path.string();
  while (!s.empty() && s.back() == '/') s.pop_back();
  return s.size() >= 5 && s.compare(s.size() - 5, 5, ".zarr") == 0;
}

int omeZarrAutoLevels(glm::ivec3 dims, int chunk) {
  return omeZarrAutoLevels(dims, glm::ivec3(chunk));
}

int omeZarrAutoLevels(glm::ivec3 dims, glm::ivec3 chunk, glm::ivec3 factors) {
  int levels = 1;
  const auto over = [&](glm::ivec3 d) {
    for (int a = 0; a < 3; ++a) {
      if (factors[a] > 1 && d[a] > chunk[a]) return true;
    }
    return false;
  };
  while (over(dims)) {
    dims = (dims + factors - 1) / factors;
    ++levels;
  }
  return levels;
}

OmeZarrWriteResult writeOmeZarr(const Volume& shape, const SlabReader& slabs, const fs::path& out,
                                const OmeZarrWriteOptions& o) {
  for (int a = 0; a < 3; ++a) {
    const int c = o.chunkXyz()[a];
    if (c < 8 || c > 1024 || c % 2 != 0) {
      throw InputError("--chunk " + std::to_string(c) + ": expected an even size in 8..1024");
    }
  }
  if (o.zarrFormat != 2 && o.zarrFormat != 3) {
    throw InputError("--zarr-format " + std::to_string(o.zarrFormat) + ": expected 2 or 3");
  }
  if (o.shard < 0 || o.shard > 64 || (o.shard > 0 && o.zarrFormat != 3)) {
    throw InputError("--shard " + std::to_string(o.shard) +
                     ": expected 1..64 chunks per shard edge, with --zarr-format 3");
  }
  const glm::ivec3 f = o.factors;
  if (f.x < 1 || f.x > 2 || f.y < 1 || f.y > 2 || f.z < 1 || f.z > 2 || f == glm::ivec3(1)) {
    throw InputError("--pyramid-factors " + std::to_string(f.z) + "," + std::to_string(f.y) + "," +
                     std::to_string(f.x) +
                     ": expected Z,Y,X each 1 (axis kept) or 2 (halved), at least one 2");
  }
  if (o.levels < 0 || o.levels > 30) {
    throw InputError("--levels " + std::to_string(o.levels) + ": expected auto or 1..30");
  }
  std::string trimmed = out.string();
  while (trimmed.size() > 1 && trimmed.back() == '/') trimmed.pop_back();
  const fs::path path(trimmed);
  // Slab buffers: one chunk-deep slab per level (a geometric series under
  // 4/3 of the finest when x and y halve; as many finest slabs as levels
  // when they are kept) plus the slab being read and its reduction.
  const glm::ivec3 d = shape.dims();
  const auto slabOf = [&](glm::ivec3 dims) {
    return std::uint64_t(dims.x) * std::uint64_t(dims.y) *
           std::uint64_t(std::min(dims.z, o.chunkXyz().z)) * bytesPerVoxel(shape.type());
  };
  std::uint64_t slabBytes = 2 * slabOf(d);
  glm::ivec3 ld = d;
  const int count = o.levels > 0 ? o.levels : omeZarrAutoLevels(d, o.chunkXyz(), f);
  for (int l = 0; l < count; ++l, ld = (ld + f - 1) / f) slabBytes += slabOf(ld);
  HostBudget::global().check(slabBytes, path.string() + ": OME-Zarr slabs of " + dimsText(d));
  std::error_code ec;
  const bool replace = fs::exists(path, ec);
  if (replace && !isZarrStore(path.string())) {
    throw InputError(path.string() + ": exists and is not an OME-Zarr store; not replacing it");
  }
  const fs::path old = path.string() + ".old-" + std::to_string(::getpid());
  std::string name = path.filename().string();
  if (const auto dot = name.find('.'); dot != std::string::npos && dot > 0) name.resize(dot);
  OmeZarrWriteResult result;
  writeAtomically(path, [&](const fs::path& temp) {
    build(shape, slabs, temp, o, name, result);
    if (replace) fs::rename(path, old);
  });
  if (replace) fs::remove_all(old, ec);
  return result;
}

OmeZarrWriteResult writeOmeZarr(const Volume& volume, const fs::path& path,
                                const OmeZarrWriteOptions& options) {
  const std::size_t sliceBytes =
      std::size_t(volume.dims().x) * std::size_t(volume.dims().y) * bytesPerVoxel(volume.type());
  return writeOmeZarr(
      volume,
      [&](int z0, int z1) {
        Volume part =
            Volume::allocate({volume.dims().x, volume.dims().y, z1 - z0}, volume.type(), "slab");
        std::memcpy(part.bytes().data(), volume.bytes().data() + std::size_t(z0) * sliceBytes,
                    std::size_t(z1 - z0) * sliceBytes);
        part.invalidateRange();
        return part;
      },
      path, options);
}

}  // namespace tessera
