// PLACEHOLDER until the NIfTI writer lands (issue 7); replaced wholesale.
#include "tessera/io/NiftiWriter.h"

#include "tessera/core/Error.h"

namespace tessera {
void writeNifti(const Volume&, const std::filesystem::path& p) {
  throw InputError(p.string() + ": NIfTI writing not supported yet");
}
}  // namespace tessera
