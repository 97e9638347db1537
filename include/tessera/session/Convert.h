#pragma once
// What `tessera convert` and Python's tessera.convert do to a volume before
// writing it, and how they write an OME-Zarr store: one reading of the
// options for both front ends (crop, downsample, chunk shape, levels,
// compressor, Zarr format, shards, pyramid factors). Errors name the option as the CLI
// spells it ("--crop '...': ...").
#include <string>

#include <glm/vec3.hpp>

#include "tessera/core/Volume.h"
#include "tessera/io/ZarrWriter.h"

namespace tessera::session {

struct ConvertRequest {
  std::string crop;        // "x0:x1,y0:y1,z0:z1", voxels, end exclusive ("": none)
  std::string downsample;  // "N" or "AxBxC", box filter factors ("": none)
  // OME-Zarr output.
  std::string chunk = "64";  // 64, 128 or "Z,Y,X" (even, 8..1024)
  std::string levels = "auto";
  std::string compressor = "zstd";
  int zarrFormat = 2;  // 2: NGFF 0.4 on Zarr v2; 3: NGFF 0.5 on Zarr v3
  int shard = 0;       // chunks per shard edge (v3), 0: unsharded
  // Each level's factor against the one before, "Z,Y,X" (array order, as
  // --chunk): 2 halves an axis, 1 keeps it; "1,2,2" is microscopy's.
  std::string pyramidFactors = "2,2,2";
};

// "N" or "AxBxC" as x, y, z factors (>= 1).
glm::ivec3 parseDownsample(const std::string& text);
// "x0:x1,y0:y1,z0:z1" within `dims`: the half-open box [lo, hi).
std::pair<glm::ivec3, glm::ivec3> parseCrop(const std::string& text, glm::ivec3 dims);
// Voxels [lo, hi) of `v` with its geometry (the origin moved to lo).
Volume cropVolume(const Volume& v, glm::ivec3 lo, glm::ivec3 hi);

// The OME-Zarr write options the request names (no progress callback);
// checked before anything is read, so that a typo fails at once.
OmeZarrWriteOptions zarrWriteOptions(const ConvertRequest& request);

// `v` cropped, then downsampled, as the request says (unchanged when it
// says neither).
Volume cropAndDownsample(Volume v, const ConvertRequest& request);

}  // namespace tessera::session
