// PLACEHOLDER until the MetaImage reader lands (issue 7); replaced wholesale.
#include "tessera/io/MetaImageReader.h"

#include "tessera/core/Error.h"

namespace tessera {
Volume readMetaImage(const std::filesystem::path& p) {
  throw InputError(p.string() + ": MetaImage not supported yet");
}
void writeMetaImage(const Volume&, const std::filesystem::path& p, bool) {
  throw InputError(p.string() + ": MetaImage not supported yet");
}
}  // namespace tessera
