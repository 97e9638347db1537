// PLACEHOLDER until the PVM/raw readers land (issue 7); replaced wholesale.
#include "tessera/io/PvmReader.h"

#include "tessera/core/Error.h"

namespace tessera {
Volume readPvm(const std::filesystem::path& p) {
  throw InputError(p.string() + ": PVM not supported yet");
}
void writePvm(const Volume&, const std::filesystem::path& p) {
  throw InputError(p.string() + ": PVM not supported yet");
}
Volume readRawWithSidecar(const std::filesystem::path& p) {
  throw InputError(p.string() + ": raw not supported yet");
}
void writeRawWithSidecar(const Volume&, const std::filesystem::path& p) {
  throw InputError(p.string() + ": raw not supported yet");
}
}  // namespace tessera
