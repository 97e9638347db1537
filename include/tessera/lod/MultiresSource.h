#pragma once
// A multiresolution volume that is never held whole: a pyramid of levels,
// each readable one box at a time (Schultz 2016 section 7.1.2 and 7.3;
// DESIGN.md "Large data"). Level 0 is the finest; level l+1 divides each
// axis of level l by an integer factor, its dims rounded up or down: 2 on
// every axis (tessera convert), or 1 on an axis it keeps (microscopy's
// (1, 2, 2) scales keep z; lod/LevelScale.h). A chunked store on disk or over HTTP
// (OME-Zarr) implements it with bounded reads; an in-core volume implements
// it by downsampling on request. The bricked layout and the streaming
// scheduler read through this interface only, so they do not know where
// the voxels live.
#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"

namespace tessera::lod {

// One level of the pyramid.
struct LevelInfo {
  glm::ivec3 dims{0};       // voxels along x, y, z
  glm::vec3 spacing{1.0f};  // mm per voxel along the index axes
  glm::ivec3 chunk{0};      // the store's natural read unit (0: none)
};

// A box of voxels [begin, end) in one level's index space.
struct VoxelBox {
  glm::ivec3 begin{0};
  glm::ivec3 end{0};
  glm::ivec3 size() const { return end - begin; }
  std::uint64_t count() const {
    const glm::ivec3 s = size();
    return s.x <= 0 || s.y <= 0 || s.z <= 0
               ? 0
               : std::uint64_t(s.x) * std::uint64_t(s.y) * std::uint64_t(s.z);
  }
};

class MultiresSource {
 public:
  virtual ~MultiresSource() = default;

  // The finest level's shape: dims, scalar type, geometry (spacing,
  // direction, origin), value range and window; it holds no voxels. Every
  // level shares its scalar type, world box and window.
  virtual const Volume& shape() const = 0;

  virtual int levelCount() const = 0;
  virtual LevelInfo levelInfo(int level) const = 0;

  // The voxels of `box` (clamped to the level's dims by the caller: a box
  // outside the level is an error) as a Volume of box.size() voxels with
  // the source's scalar type; its geometry is the level's spacing with the
  // origin at the box's first voxel. Thread-safe: the streaming scheduler
  // calls it from worker threads. Errors (a corrupt or unreachable chunk)
  // throw tessera::Error naming the chunk or URL; the caller keeps the
  // coarser level on screen and retries later.
  virtual Volume readBox(int level, const VoxelBox& box) const = 0;

  // Whether readBox(level, box) can return now without waiting on slow
  // storage. Sources whose storage answers asynchronously (the browser's
  // fetch(), which the single-threaded page must not block on) start the
  // reads the box needs and say false until they have arrived; the
  // streamer then reads other bricks and asks again next frame.
  virtual bool prefetch(int level, const VoxelBox& box) const {
    (void)level;
    (void)box;
    return true;
  }

  // Whether every coarser voxel is the mean of the (up to 8) finer voxels
  // under it. Only then does a coarse brick's range bound the values of
  // the bricks under it (see meanPyramidBound()), which lets the bricks
  // layout leave unread bricks out when the TF makes the bound transparent.
  // Other reductions (decimation, a Gaussian, an analytic field per level)
  // say nothing of finer values: such bricks are read before they can be
  // skipped. Default false.
  virtual bool meanPyramid() const { return false; }
  // Whether readBox is a copy out of host memory: no storage, no decode, no
  // chunk grid. Then what a consumer cuts the levels into decides nothing
  // about what is read (the bricks layout sizes its bricks for the ray march
  // alone). Default false.
  virtual bool readsFromHostMemory() const { return false; }
  // Decoded data the source keeps between reads (a store's decoded chunks,
  // io/ZarrChunkCache.h), which the bricks layout counts inside the device
  // profile's host budget beside its own brick cache: the bytes the source
  // would keep (0: it keeps none), a smaller budget the layout gives it out
  // of the host budget (thread-safe; never more than it would keep), and
  // the most it has held so far.
  virtual std::uint64_t decodedCacheWanted() const { return 0; }
  virtual void limitDecodedCache(std::uint64_t bytes) const { (void)bytes; }
  virtual std::uint64_t decodedCachePeakBytes() const { return 0; }

  // A short description for logs and `tessera info` (path or URL).
  virtual std::string describe() const = 0;
};

}  // namespace tessera::lod
