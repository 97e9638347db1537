#include "bench/BenchPeers.h"

#include <sys/wait.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tessera/core/Error.h"

#ifndef TESSERA_SOURCE_DIR
#define TESSERA_SOURCE_DIR ""
#endif

namespace tessera::app {

namespace {

namespace fs = std::filesystem;

struct PeersBenchOptions {
  bool vtk = false;
  bool web = false;
  std::string sourceDir = TESSERA_SOURCE_DIR;
  std::string args;
};

PeersBenchOptions& options() {
  static PeersBenchOptions o;
  return o;
}

// The program `name` on PATH, or "" (what `command -v` finds).
std::string onPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return "";
}

void require(const std::string& program, const std::string& why) {
  if (onPath(program).empty()) {
    throw InputError("tessera bench: " + program + " not found on PATH; " + why +
                     " (scripts/setup.sh installs it)");
  }
}

// This executable, so that the benchmark times the binary the user ran.
std::string selfPath() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "";
  buf[n] = '\0';
  return buf;
}

std::vector<std::string> splitArgs(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  std::string word;
  while (in >> word) out.push_back(word);
  return out;
}

// Runs argv in `dir`, waits, and turns a failure into an Error.
void runProgram(const std::vector<std::string>& argv, const fs::path& dir) {
  std::string shown;
  for (const std::string& a : argv) shown += (shown.empty() ? "" : " ") + a;
  std::fprintf(stderr, "tessera bench: running %s (in %s)\n", shown.c_str(), dir.c_str());
  std::fflush(stderr);
  std::fflush(stdout);
  const pid_t pid = ::fork();
  if (pid < 0) throw Error("tessera bench: cannot start " + argv[0]);
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) _exit(127);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(argv[0].c_str(), args.data());
    std::fprintf(stderr, "tessera bench: cannot execute %s\n", argv[0].c_str());
    _exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  throw Error("tessera bench: " + shown + " failed (" +
              (WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                 : "signal " + std::to_string(WTERMSIG(status))) +
              ")");
}

fs::path script(const PeersBenchOptions& o, const std::string& relative) {
  if (o.sourceDir.empty()) {
    throw InputError("tessera bench: this binary does not know its source tree; pass --source-dir");
  }
  const fs::path path = fs::path(o.sourceDir) / relative;
  if (!fs::exists(path)) {
    throw InputError("tessera bench: " + path.string() +
                     " not found: the peer benchmarks run from a source checkout; pass "
                     "--source-dir DIR (the directory holding bench/)");
  }
  return path;
}

}  // namespace

void addPeersBenchOptions(CLI::App* bench) {
  PeersBenchOptions& o = options();
  bench->add_flag("--peers", o.vtk,
                  "Tessera vs VTK 9.1 (GPU and fixed-point CPU ray casters) side by side, "
                  "alternating: runs bench/peers/peers.py with this binary (needs python3-vtk9 "
                  "and xvfb-run; bench/peers/README.md)");
  bench->add_flag("--web-peers", o.web,
                  "The web page (WebGL 2 and 1) vs NiiVue and vtk.js in headless Chromium, "
                  "alternating: runs bench/web-peers/run.sh (needs node, npm, chromium, "
                  "emscripten; docs/benchmarks.md)");
  bench
      ->add_option("--source-dir", o.sourceDir,
                   "With --peers/--web-peers: the source tree holding bench/")
      ->capture_default_str();
  bench->add_option("--peers-args", o.args,
                    "With --peers/--web-peers: arguments for the script, as one string with '=', "
                    "e.g. --peers-args=\"--sizes 512x512 --steps 0.5,1\" (see its --help)");
}

bool runPeersBenchIfAsked() {
  const PeersBenchOptions& o = options();
  if (!o.vtk && !o.web) return false;
  if (o.vtk && o.web) throw InputError("tessera bench: --peers and --web-peers run one at a time");
  const std::vector<std::string> extra = splitArgs(o.args);
  if (o.vtk) {
    const fs::path py = script(o, "bench/peers/peers.py");
    if (::access("/usr/bin/python3", X_OK) != 0) {
      throw InputError(
          "tessera bench --peers: /usr/bin/python3 not found (Debian's python3-vtk9 "
          "needs Debian's python3)");
    }
    require("xvfb-run", "VTK's renderers need an X server here");
    std::vector<std::string> argv = {"/usr/bin/python3", py.string(), "--tessera", selfPath()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    runProgram(argv, o.sourceDir);
    return true;
  }
  const fs::path sh = script(o, "bench/web-peers/run.sh");
  require("node", "the browser benchmark runs under Node");
  require("npm", "the peers' pinned packages install with npm ci");
  if (::access("/usr/bin/chromium", X_OK) != 0) {
    throw InputError("tessera bench --web-peers: /usr/bin/chromium not found (Debian's chromium)");
  }
  std::vector<std::string> argv = {"/bin/bash", sh.string()};
  argv.insert(argv.end(), extra.begin(), extra.end());
  runProgram(argv, o.sourceDir);
  return true;
}

}  // namespace tessera::app
