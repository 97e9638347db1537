#pragma once
// Runs a shell command line (the desktop viewer under xvfb-run, say) and
// captures its exit status and its output, stdout and stderr together.
#include <cstdio>
#include <string>

namespace tessera::test {

struct CommandRun {
  int status = -1;  // pclose's status; -1 when the command could not start
  std::string output;
};

inline CommandRun runCommand(const std::string& command) {
  CommandRun r;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) r.output += buf;
  r.status = pclose(p);
  return r;
}

}  // namespace tessera::test
