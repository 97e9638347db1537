#include "tessera/gpu/ProgramCache.h"

namespace tessera::gpu {

const Program& ProgramCache::get(const std::string& key, const std::function<Program()>& build) {
  auto it = programs_.find(key);
  if (it != programs_.end()) return it->second;
  return programs_.emplace(key, build()).first->second;
}

}  // namespace tessera::gpu
