#pragma once
// A real PACS for the DICOMweb tests: Debian's Orthanc with its DICOMweb
// plugin (and no other), started on a free port of 127.0.0.1 with a
// temporary storage folder and a generated config, stopped (SIGTERM, then
// SIGKILL) when the object goes, also when a test fails; it dies with the
// test process too (PR_SET_PDEATHSIG). Instances are stored through
// Orthanc's REST API (POST /instances), by curl.
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "io/ZarrTestSupport.h"

namespace tessera::test {

class OrthancServer {
 public:
  static constexpr const char* kBinary = "/usr/sbin/Orthanc";
  static constexpr const char* kPlugin = "/usr/share/orthanc/plugins/libOrthancDicomWeb.so";

  // Why the tests cannot run here ("" when they can).
  static std::string missing() {
    if (!std::filesystem::exists(kBinary))
      return std::string(kBinary) + " is not installed (orthanc)";
    if (!std::filesystem::exists(kPlugin)) {
      return std::string(kPlugin) + " is not installed (orthanc-dicomweb)";
    }
    return "";
  }

  // `user`/`password` non-empty: HTTP basic authentication required.
  explicit OrthancServer(const std::filesystem::path& folder, const std::string& user = "",
                         const std::string& password = "")
      : port_(freePort()), folder_(folder), user_(user), password_(password) {
    std::filesystem::create_directories(folder / "storage");
    const std::filesystem::path config = folder / "orthanc.json";
    std::ofstream f(config);
    f << "{\"Name\": \"tessera-test\", \"StorageDirectory\": \"" << (folder / "storage").string()
      << "\", \"IndexDirectory\": \"" << (folder / "storage").string()
      << "\", \"HttpPort\": " << port_
      << ", \"DicomServerEnabled\": false, \"RemoteAccessAllowed\": false"
      << ", \"HttpCompressionEnabled\": false, \"ConcurrentJobs\": 1"
      << ", \"Plugins\": [\"" << kPlugin << "\"]"
      << ", \"DicomWeb\": {\"Enable\": true, \"Root\": \"/dicom-web/\"}"
      << ", \"AuthenticationEnabled\": " << (user.empty() ? "false" : "true");
    if (!user.empty()) f << ", \"RegisteredUsers\": {\"" << user << "\": \"" << password << "\"}";
    f << "}\n";
    f.close();
    pid_ = ::fork();
    if (pid_ == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      const std::string log = (folder / "orthanc.log").string();
      std::freopen(log.c_str(), "w", stdout);
      std::freopen(log.c_str(), "a", stderr);
      ::execl(kBinary, kBinary, config.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    if (!waitForPort(port_, 20.0) || !answers()) {
      stop();
      throw std::runtime_error("Orthanc did not start on port " + std::to_string(port_) + " (see " +
                               (folder / "orthanc.log").string() + ")");
    }
  }
  ~OrthancServer() { stop(); }
  OrthancServer(const OrthancServer&) = delete;
  OrthancServer& operator=(const OrthancServer&) = delete;

  int port() const { return port_; }
  std::string root() const { return "http://127.0.0.1:" + std::to_string(port_); }
  std::string dicomWebRoot() const { return root() + "/dicom-web"; }

  // Stores every file of `folder` (POST /instances); false when one is refused.
  bool upload(const std::filesystem::path& folder) const {
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(folder)) {
      if (e.is_regular_file()) files.push_back(e.path());
    }
    // One curl for all files, each its own request (--next: data options
    // are per request, else curl would send them all as one body).
    std::string cmd = "curl";
    for (const auto& file : files) {
      cmd += " -sf" + auth() + " -X POST --data-binary @'" + file.string() + "' '" + root() +
             "/instances' -o /dev/null --next";
    }
    cmd.resize(cmd.size() - std::string(" --next").size());
    return std::system((cmd + " 2>/dev/null").c_str()) == 0;
  }

  // Kills the server (a PACS stopped mid-series).
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    for (int i = 0; i < 100; ++i) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  std::string auth() const { return user_.empty() ? "" : " -u '" + user_ + ":" + password_ + "'"; }
  bool answers() const {
    for (int i = 0; i < 100; ++i) {
      const std::string cmd =
          "curl -sf" + auth() + " -o /dev/null '" + root() + "/system' 2>/dev/null";
      if (std::system(cmd.c_str()) == 0) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

  int port_;
  std::filesystem::path folder_;
  std::string user_;
  std::string password_;
  pid_t pid_ = -1;
};

}  // namespace tessera::test
