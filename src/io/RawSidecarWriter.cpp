// Raw voxels with a JSON sidecar: the writer (the format is described in
// io/RawSidecarReader.cpp).
#include "tessera/io/RawSidecarWriter.h"

#include <string>

#include <nlohmann/json.hpp>

#include "io/OutputFile.h"
#include "tessera/core/Error.h"
#include "tessera/io/VolumeWriter.h"

namespace tessera {

void writeRawWithSidecar(const Volume& volume, const std::filesystem::path& path) {
  if (!volume.hasData()) throw InputError(path.string() + ": cannot write a volume without voxels");
  const glm::ivec3 d = volume.dims();
  const glm::dvec3 s = volume.spacing();
  const glm::dvec3 o = volume.origin();
  // nlohmann writes doubles with enough digits to read back the same value.
  nlohmann::ordered_json sidecar;
  sidecar["dims"] = {d.x, d.y, d.z};
  sidecar["type"] = std::string(scalarTypeName(volume.type()));
  sidecar["spacing"] = {s.x, s.y, s.z};
  sidecar["origin"] = {o.x, o.y, o.z};
  // + 0.0 writes -0 as 0.
  const glm::dmat3 dir = volume.direction() + glm::dmat3(0.0);
  sidecar["direction"] = {{dir[0].x, dir[0].y, dir[0].z},
                          {dir[1].x, dir[1].y, dir[1].z},
                          {dir[2].x, dir[2].y, dir[2].z}};
  sidecar["endian"] = "little";
  sidecar["offset"] = 0;
  sidecar["file"] = path.filename().string();
  const std::string text = sidecar.dump(2) + "\n";

  std::filesystem::path sidecarPath = path;
  sidecarPath += ".json";
  // Both files are complete before either replaces an older version: the
  // sidecar (which makes the data readable) is renamed into place inside
  // the raw file's write, just before the raw file.
  writeAtomically(path, [&](const std::filesystem::path& rawTemp) {
    io_detail::OutputFile raw(rawTemp);
    io_detail::forEachLittleEndianChunk(
        volume, [&](const std::byte* chunk, std::size_t n) { raw.write(chunk, n); });
    raw.close();
    writeAtomically(sidecarPath, [&](const std::filesystem::path& sidecarTemp) {
      io_detail::OutputFile out(sidecarTemp);
      out.write(text);
      out.close();
    });
  });
}

}  // namespace tessera
