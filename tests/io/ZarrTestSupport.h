#pragma once
// What the OME-Zarr tests share: Debian's python3 with zarr-python (the
// independent writer and reader), a child process started and stopped by
// the test (nginx, the fault-injecting proxy), a free local port, and
// volumes of random voxels.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "io/IoFixtures.h"
#include "tessera/core/Volume.h"

namespace tessera::test {

inline constexpr const char* kZarrPython = "/usr/bin/python3";

inline std::filesystem::path zarrScript(const std::string& name) {
  return std::filesystem::path(TESSERA_TEST_DATA_DIR) / ".." / "zarr" / name;
}

// Empty when zarr-python is there, else why not.
inline std::string zarrPythonMissing() {
  static const bool ok =
      std::system((std::string(kZarrPython) + " -c 'import zarr, numcodecs, numpy' >/dev/null 2>&1")
                      .c_str()) == 0;
  return ok ? "" : std::string(kZarrPython) + " cannot import zarr/numcodecs (python3-zarr)";
}

// A port nothing listens on right now (bound and released).
inline int freePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    ::close(fd);
    throw std::runtime_error("no free port");
  }
  ::close(fd);
  return ntohs(a.sin_port);
}

// True once something accepts connections on 127.0.0.1:port.
inline bool waitForPort(int port, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    const bool up = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    ::close(fd);
    if (up) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// A child process with its stdout on a pipe; SIGTERM and reaped when the
// object goes.
class ChildProcess {
 public:
  explicit ChildProcess(const std::vector<std::string>& argv) {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("pipe failed");
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[1], 1);
      ::close(fds[0]);
      ::close(fds[1]);
      std::vector<char*> args;
      for (const std::string& s : argv) args.push_back(const_cast<char*>(s.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    ::close(fds[1]);
    out_ = ::fdopen(fds[0], "r");
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
    if (out_) std::fclose(out_);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // The next line the child prints ("" at the end of its output).
  std::string readLine() {
    char buf[256];
    if (!std::fgets(buf, sizeof buf, out_)) return "";
    std::string s(buf);
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    return s;
  }

 private:
  pid_t pid_ = -1;
  FILE* out_ = nullptr;
};

// nginx serving `root` on a free port of 127.0.0.1, from a generated
// config in `prefix`; stopped when the object goes. `locations`: more of the
// server block, e.g. "location = /s.zarr/0/1/1/1 { return 500; }".
class Nginx {
 public:
  static constexpr const char* kBinary = "/usr/sbin/nginx";
  Nginx(const std::filesystem::path& root, const std::filesystem::path& prefix,
        const std::string& locations = "")
      : port_(freePort()) {
    std::filesystem::create_directories(prefix / "tmp");
    const std::string p = prefix.string();
    FILE* f = std::fopen((prefix / "nginx.conf").c_str(), "w");
    std::fprintf(f,
                 "daemon off;\nworker_processes 1;\npid %s/nginx.pid;\nerror_log %s/error.log;\n"
                 "events { worker_connections 64; }\n"
                 "http {\n access_log off;\n client_body_temp_path %s/tmp;\n"
                 " proxy_temp_path %s/tmp;\n fastcgi_temp_path %s/tmp;\n uwsgi_temp_path %s/tmp;\n"
                 " scgi_temp_path %s/tmp;\n"
                 " server { listen 127.0.0.1:%d; root %s; location / { } %s }\n}\n",
                 p.c_str(), p.c_str(), p.c_str(), p.c_str(), p.c_str(), p.c_str(), p.c_str(), port_,
                 root.c_str(), locations.c_str());
    std::fclose(f);
    process_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{kBinary, "-p", p, "-c", (prefix / "nginx.conf").string()});
    if (!waitForPort(port_, 10.0)) throw std::runtime_error("nginx did not start");
  }
  int port() const { return port_; }
  std::string url(const std::string& path) const {
    return "http://127.0.0.1:" + std::to_string(port_) + "/" + path;
  }

 private:
  int port_;
  std::unique_ptr<ChildProcess> process_;
};

}  // namespace tessera::test
