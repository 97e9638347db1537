#include "tessera/io/ByteSource.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "tessera/core/Error.h"

namespace tessera {

namespace fs = std::filesystem;

namespace {

// The messages of a missing or unreadable input, shared by the check before
// opening and the open itself.
void requireRegularFile(const fs::path& path) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw InputError(path.string() + ": no such file");
  if (fs::is_directory(status)) {
    throw InputError(path.string() + ": is a directory, expected a volume file");
  }
  if (!fs::is_regular_file(status)) throw InputError(path.string() + ": is not a regular file");
}

std::string fileNameOf(const std::string& name) {
  return fs::path(name).filename().string();
}

}  // namespace

FileSource::FileSource(const fs::path& path) : ByteSource(path.string()) {
  requireRegularFile(path);
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw InputError(name() + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int err = errno;
    ::close(fd_);
    throw InputError(name() + ": cannot read its size: " + std::strerror(err));
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

FileSource::~FileSource() {
  if (fd_ >= 0) ::close(fd_);
}

std::size_t FileSource::read(std::uint64_t offset, std::byte* dst, std::size_t n) const {
  std::size_t done = 0;
  while (done < n && offset + done < size_) {
    const ssize_t got = ::pread(fd_, dst + done, n - done, static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw InputError(name() + ": read error: " + std::strerror(errno));
    if (got == 0) break;  // the file shrank while we read it
    done += static_cast<std::size_t>(got);
  }
  return done;
}

MemorySource::MemorySource(std::string name, std::vector<std::byte> bytes)
    : ByteSource(std::move(name)), owned_(std::move(bytes)), bytes_(owned_) {}

MemorySource::MemorySource(std::string name, std::span<const std::byte> borrowed)
    : ByteSource(std::move(name)), bytes_(borrowed) {}

std::size_t MemorySource::read(std::uint64_t offset, std::byte* dst, std::size_t n) const {
  if (offset >= bytes_.size()) return 0;
  const std::size_t take =
      static_cast<std::size_t>(std::min<std::uint64_t>(n, bytes_.size() - offset));
  std::memcpy(dst, bytes_.data() + offset, take);
  return take;
}

std::string FolderFiles::resolve(const ByteSource& from, const std::string& name) const {
  const fs::path p(name);
  if (p.is_absolute()) return name;
  return (fs::path(from.name()).parent_path() / p).string();
}

bool FolderFiles::contains(const std::string& resolved) const {
  std::error_code ec;
  return fs::is_regular_file(resolved, ec);
}

std::unique_ptr<ByteSource> FolderFiles::open(const std::string& resolved) const {
  return std::make_unique<FileSource>(resolved);
}

std::vector<std::string> FolderFiles::filesBeside(const ByteSource& from) const {
  // Named as `from` is: "x.dcm" beside "x.dcm", not "./x.dcm".
  const fs::path parent = fs::path(from.name()).parent_path();
  const fs::path folder = parent.empty() ? fs::path(".") : parent;
  std::vector<std::string> out;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code tec;
    if (it->is_regular_file(tec)) out.push_back((parent / it->path().filename()).string());
  }
  if (ec) throw InputError(folder.string() + ": cannot list the folder: " + ec.message());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> MemoryFiles::filesBeside(const ByteSource&) const {
  return names();
}

void MemoryFiles::add(std::string name, std::vector<std::byte> bytes) {
  auto owned = std::make_shared<const std::vector<std::byte>>(std::move(bytes));
  const std::span<const std::byte> view(*owned);
  files_.push_back({std::move(name), std::move(owned), view});
}

void MemoryFiles::add(std::string name, std::span<const std::byte> borrowed) {
  files_.push_back({std::move(name), nullptr, borrowed});
}

std::vector<std::string> MemoryFiles::names() const {
  std::vector<std::string> out;
  for (const Entry& e : files_) out.push_back(e.name);
  return out;
}

const MemoryFiles::Entry* MemoryFiles::find(const std::string& name) const {
  // A dropped folder's files may share a file name in different subfolders.
  for (const Entry& e : files_) {
    if (e.name == name) return &e;
  }
  const std::string wanted = fileNameOf(name);
  for (const Entry& e : files_) {
    if (fileNameOf(e.name) == wanted) return &e;
  }
  return nullptr;
}

std::string MemoryFiles::resolve(const ByteSource&, const std::string& name) const {
  return fileNameOf(name);
}

bool MemoryFiles::contains(const std::string& resolved) const {
  return find(resolved) != nullptr;
}

std::unique_ptr<ByteSource> MemoryFiles::open(const std::string& resolved) const {
  const Entry* e = find(resolved);
  if (e == nullptr) {
    std::string opened;
    for (const Entry& f : files_) opened += (opened.empty() ? "" : ", ") + fileNameOf(f.name);
    throw InputError(resolved + ": no such file among those opened together (" +
                     (opened.empty() ? std::string("none") : opened) +
                     "); open it together with them");
  }
  return std::make_unique<MemorySource>(e->name, e->bytes);
}

}  // namespace tessera
