#pragma once
// What every reader in io reads: one file's bytes, on disk or in memory
// (ByteSource), and the files beside it that it may name (FileSet: a .nhdr's
// data file, a .mhd's .raw, a .hdr's .img, a JSON sidecar's raw file). The
// CLI reads files on disk, the browser the files a user picked or dropped,
// held in memory; tests and fuzzers use either. All run the same parsers.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace tessera {

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  ByteSource(const ByteSource&) = delete;
  ByteSource& operator=(const ByteSource&) = delete;

  // The name the user knows the file by (a path on disk, a file name in the
  // browser): every error about the file starts with it, and its extension
  // picks the reader.
  const std::string& name() const { return name_; }
  virtual std::uint64_t size() const = 0;
  // Copies up to `n` bytes from `offset` on into `dst`; fewer only at the
  // end. InputError naming the file if the bytes cannot be read.
  virtual std::size_t read(std::uint64_t offset, std::byte* dst, std::size_t n) const = 0;

 protected:
  explicit ByteSource(std::string name) : name_(std::move(name)) {}

 private:
  std::string name_;
};

// A regular file on disk, kept open while the object lives. InputError
// naming the path if it does not exist, is a folder or something else that
// is not a regular file.
class FileSource final : public ByteSource {
 public:
  explicit FileSource(const std::filesystem::path& path);
  ~FileSource() override;
  std::uint64_t size() const override { return size_; }
  std::size_t read(std::uint64_t offset, std::byte* dst, std::size_t n) const override;

 private:
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// Bytes in memory: owned, or borrowed from a caller who keeps them alive
// while they are read.
class MemorySource final : public ByteSource {
 public:
  MemorySource(std::string name, std::vector<std::byte> bytes);
  MemorySource(std::string name, std::span<const std::byte> borrowed);
  std::uint64_t size() const override { return bytes_.size(); }
  std::size_t read(std::uint64_t offset, std::byte* dst, std::size_t n) const override;

 private:
  std::vector<std::byte> owned_;
  std::span<const std::byte> bytes_;
};

// Where a reader finds a file that another file names.
class FileSet {
 public:
  virtual ~FileSet() = default;
  // What `name`, written inside `from`, refers to (for messages and for
  // contains/open): a relative name is relative to `from`'s folder.
  virtual std::string resolve(const ByteSource& from, const std::string& name) const = 0;
  // True if `resolved` is a regular file here.
  virtual bool contains(const std::string& resolved) const = 0;
  // The file; InputError starting with `resolved` if it is missing.
  virtual std::unique_ptr<ByteSource> open(const std::string& resolved) const = 0;
  // The files beside `from` (its folder's regular files, `from` included,
  // not searched recursively; all files held in memory), as names `open`
  // takes, in a stable order: a DICOM series is read from them.
  virtual std::vector<std::string> filesBeside(const ByteSource& from) const = 0;
  // True when the names are paths of files on disk (readers that open
  // files themselves, such as DCMTK's, can read them).
  virtual bool onDisk() const { return false; }
};

// Files on disk.
class FolderFiles final : public FileSet {
 public:
  std::string resolve(const ByteSource& from, const std::string& name) const override;
  bool contains(const std::string& resolved) const override;
  std::unique_ptr<ByteSource> open(const std::string& resolved) const override;
  std::vector<std::string> filesBeside(const ByteSource& from) const override;
  bool onDisk() const override { return true; }
};

// Files held in memory and found by their whole name, else by file name
// (folders in a name are ignored): the browser's picked or dropped files, and those of tests and
// fuzzers.
class MemoryFiles final : public FileSet {
 public:
  void add(std::string name, std::vector<std::byte> bytes);
  // Borrowed: the bytes must outlive every read.
  void add(std::string name, std::span<const std::byte> borrowed);
  std::vector<std::string> names() const;

  std::string resolve(const ByteSource& from, const std::string& name) const override;
  bool contains(const std::string& resolved) const override;
  std::unique_ptr<ByteSource> open(const std::string& resolved) const override;
  std::vector<std::string> filesBeside(const ByteSource& from) const override;

 private:
  struct Entry {
    std::string name;
    std::shared_ptr<const std::vector<std::byte>> owned;
    std::span<const std::byte> bytes;
  };
  const Entry* find(const std::string& name) const;
  std::vector<Entry> files_;
};

}  // namespace tessera
