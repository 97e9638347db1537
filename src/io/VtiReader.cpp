// PLACEHOLDER until the VTI reader lands (issue 7); replaced wholesale.
#include "tessera/io/VtiReader.h"

#include "tessera/core/Error.h"

namespace tessera {
Volume readVti(const std::filesystem::path& p) {
  throw InputError(p.string() + ": VTI not supported yet");
}
void writeVti(const Volume&, const std::filesystem::path& p, bool) {
  throw InputError(p.string() + ": VTI not supported yet");
}
}  // namespace tessera
