#pragma once
// Runs the `tessera` executable as a user's shell would, capturing its exit
// code, stdout and stderr (separately), and the wall time.
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/TestSupport.h"

namespace tessera::test {

struct CliRun {
  int exitCode;
  std::string out;
  std::string err;
  double seconds;
};

inline CliRun runCli(const std::string& args) {
  const TempDir tmp;
  const auto errPath = tmp / "stderr.txt";
  const std::string cmd = std::string(TESSERA_CLI_PATH) + " " + args + " 2>" + errPath.string();
  const auto t0 = std::chrono::steady_clock::now();
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf{};
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int status = pclose(p);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream err;
  err << std::ifstream(errPath).rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out, err.str(), s};
}

// Runs `args`, which must succeed, and parses what it prints (--json);
// a failure is thrown with the command's message.
inline nlohmann::json runCliJson(const std::string& args) {
  const CliRun r = runCli(args);
  if (r.exitCode != 0) {
    throw std::runtime_error("tessera " + args + ": exit " + std::to_string(r.exitCode) + ": " +
                             r.err);
  }
  return nlohmann::json::parse(r.out);
}

// Runs `args`, which must fail with `needle` in its message (one line:
// what a user sees).
inline void expectFailure(const std::string& args, const std::string& needle) {
  const CliRun r = runCli(args);
  EXPECT_NE(r.exitCode, 0) << args;
  EXPECT_NE(r.err.find(needle), std::string::npos) << args << ": " << r.err;
}

inline int countLines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

}  // namespace tessera::test
