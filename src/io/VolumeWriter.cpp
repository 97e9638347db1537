#include "tessera/io/VolumeWriter.h"

#include <unistd.h>

#include <atomic>
#include <string>

#include "tessera/core/Error.h"
#include "tessera/core/OutputPath.h"
#include "tessera/io/FormatRegistry.h"

namespace tessera {

namespace fs = std::filesystem;

std::vector<std::string> writeLossNotes(const Volume& volume, const fs::path& out) {
  const VolumeFormat* format = formatForWriteName(out);
  if (format == nullptr || !format->lossNotes) return {};
  return format->lossNotes(volume);
}

void writeAtomically(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  // A device or FIFO (/dev/null) is written directly: a rename would
  // replace it with the file.
  if (writesInPlace(path)) {
    write(path);
    return;
  }
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
  const VolumeFormat* format = formatForWriteName(path);
  if (format == nullptr || !format->write) {
    throw InputError(path.string() + ": unknown output format (use " + writeExtensionsText() + ")");
  }
  // Each entry's writer makes the output appear whole: through
  // writeAtomically, or a temporary file or folder of its own renamed into place.
  format->write(volume, path);
}

}  // namespace tessera
