#pragma once
// A FIFO for tests of writers given a device or FIFO as their output: its
// read end is opened first without waiting for a writer, so that the
// writer does not wait either (the pipe holds what a test writes, up to
// 64 KiB), and drain() returns what was written once the writer closed.
// With nothing written (a writer that replaced the FIFO by a file),
// drain() returns nothing instead of waiting.
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

namespace tessera::test {

class ReadableFifo {
 public:
  explicit ReadableFifo(std::filesystem::path path) : path_(std::move(path)) {
    if (::mkfifo(path_.c_str(), 0600) != 0) {
      throw std::runtime_error(path_.string() + ": mkfifo failed");
    }
    readEnd_ = ::open(path_.c_str(), O_RDONLY | O_NONBLOCK);
    if (readEnd_ < 0) throw std::runtime_error(path_.string() + ": cannot open its read end");
  }
  ~ReadableFifo() { ::close(readEnd_); }
  ReadableFifo(const ReadableFifo&) = delete;
  ReadableFifo& operator=(const ReadableFifo&) = delete;

  const std::filesystem::path& path() const { return path_; }

  std::string drain() {
    std::string bytes;
    char buffer[4096];
    for (ssize_t n; (n = ::read(readEnd_, buffer, sizeof buffer)) > 0;) {
      bytes.append(buffer, static_cast<std::size_t>(n));
    }
    return bytes;
  }

 private:
  std::filesystem::path path_;
  int readEnd_ = -1;
};

}  // namespace tessera::test
