#pragma once
// Programs of one technique keyed by what makes them differ (layout,
// defines): built on first use, kept for the technique's life.
#include <functional>
#include <map>
#include <string>

#include "tessera/gpu/Program.h"

namespace tessera::gpu {

class ProgramCache {
 public:
  // The program for `key`, built by `build` the first time.
  const Program& get(const std::string& key, const std::function<Program()>& build);
  std::size_t size() const { return programs_.size(); }
  void clear() { programs_.clear(); }

 private:
  std::map<std::string, Program> programs_;
};

}  // namespace tessera::gpu
