#include "tessera/io/VolumeWriter.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdio>
#include <string>

#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/DicomSeriesReader.h"
#include "tessera/io/MetaImageWriter.h"
#include "tessera/io/NiftiWriter.h"
#include "tessera/io/NrrdWriter.h"
#include "tessera/io/PvmWriter.h"
#include "tessera/io/RawSidecarWriter.h"
#include "tessera/io/VtiWriter.h"
#include "tessera/io/ZarrWriter.h"

namespace tessera {

namespace fs = std::filesystem;

namespace {
bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string lowerName(const fs::path& path) {
  std::string s = path.filename().string();
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}
std::string pointText(const glm::dvec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
  return buf;
}

// PVM's header has dims, spacing and components only. writePvm keeps the
// origin in a "tessera origin:" comment that readPvm reads back but other
// PVM readers (V^3) ignore; the direction has no place at all.
std::vector<std::string> pvmLossNotes(const Volume& v) {
  const bool rotated = v.direction() != glm::dmat3(1.0);
  const bool moved = v.origin() != glm::dvec3(0.0);
  if (!rotated && !moved) return {};
  const std::string origin = "origin " + pointText(v.origin());
  if (!rotated) {
    return {"PVM stores spacing only: the " + origin +
            " is kept in a comment that only Tessera reads back"};
  }
  std::string note = "PVM stores spacing only: orientation " +
                     orientationOf(v.direction()).describe() + " is lost (read back as RAS)";
  if (moved) note += ", and the " + origin + " is kept only in a comment Tessera reads back";
  return {note};
}
}  // namespace

std::vector<std::string> writeLossNotes(const Volume& volume, const fs::path& out) {
  const std::string name = lowerName(out);
  if (isOmeZarrName(out) && volume.direction() != glm::dmat3(1.0)) {
    return {"OME-NGFF 0.4 has no orientation: other readers see the axes of orientation " +
            orientationOf(volume.direction()).describe() +
            " as RAS; Tessera reads the direction back from its \"tessera\" attribute"};
  }
  if (endsWith(name, ".pvm")) return pvmLossNotes(volume);
  const std::string text = out.string();
  const bool dicom = !text.empty() && (text.back() == '/' || endsWith(name, ".dcm.d"));
  if (dicom && volume.type() == ScalarType::F32 && volume.hasData()) {
    // DICOM stores integers with a rescale slope/intercept: f32 is quantised.
    const double error = dicomQuantisationError(volume);
    if (error > 0.0) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "DICOM stores 16-bit integers with a rescale slope: these f32 values are "
                    "quantised, max error %.3g (value range %.6g .. %.6g)",
                    error, volume.valueRange().min, volume.valueRange().max);
      return {buf};
    }
  }
  return {};
}

void writeAtomically(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  static std::atomic<int> counter{0};
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw InputError(path.string() + ": cannot write, folder " + dir.string() + " does not exist");
  }
  // Same folder (so rename is atomic) and the same file name at the end (so
  // writers that look at the extension behave as for the final name).
  const fs::path temp = dir / (".tessera-" + std::to_string(::getpid()) + "-" +
                               std::to_string(counter++) + "-" + path.filename().string());
  // Errors name the final path, not the temporary one the user never sees.
  auto rename = [&](const std::string& message) {
    std::string m = message;
    for (auto at = m.find(temp.string()); at != std::string::npos; at = m.find(temp.string())) {
      m.replace(at, temp.string().size(), path.string());
    }
    return m;
  };
  try {
    write(temp);
    fs::rename(temp, path);
  } catch (const InputError& e) {
    fs::remove_all(temp, ec);
    throw InputError(rename(e.what()));
  } catch (const BudgetError& e) {
    fs::remove_all(temp, ec);
    throw BudgetError(rename(e.what()));
  } catch (const std::exception& e) {
    fs::remove_all(temp, ec);
    throw Error(rename(e.what()));
  }
}

void writeVolume(const Volume& volume, const fs::path& path) {
  if (!volume.hasData()) throw Error(path.string() + ": no voxels to write");
  const std::string name = lowerName(path);
  const std::string text = path.string();
  if (isOmeZarrName(path)) {
    writeOmeZarr(volume, path);  // a temporary folder renamed into place
  } else if (endsWith(name, ".nrrd")) {
    writeAtomically(path, [&](const fs::path& t) { writeNrrd(volume, t, true); });
  } else if (endsWith(name, ".nii") || endsWith(name, ".nii.gz")) {
    writeNifti(volume, path);  // through writeAtomically itself
  } else if (endsWith(name, ".mha")) {
    writeAtomically(path, [&](const fs::path& t) { writeMetaImage(volume, t, true); });
  } else if (endsWith(name, ".vti")) {
    writeAtomically(path, [&](const fs::path& t) { writeVti(volume, t, true); });
  } else if (endsWith(name, ".pvm")) {
    writePvm(volume, path);  // through writeAtomically itself
  } else if (endsWith(name, ".raw")) {
    // Two files, each through its own temporary file: the data first, then
    // the sidecar that names it and makes it readable.
    writeRawWithSidecar(volume, path);
  } else if (!text.empty() && (text.back() == '/' || endsWith(name, ".dcm.d"))) {
    writeDicomSeries(volume, path);  // writes a temporary folder and renames it
  } else {
    throw InputError(text +
                     ": unknown output format (use .nrrd, .nii, .nii.gz, .mha, .vti, .pvm, .raw, "
                     "a folder name ending in .ome.zarr (OME-Zarr) or in / for a DICOM series)");
  }
}

}  // namespace tessera
