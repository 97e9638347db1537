#pragma once
// A volume's voxel bytes: owned, or borrowed from another owner (a numpy
// array handed to the Python module) whose memory `lender` keeps alive.
// Copying borrowed voxels copies them into owned storage, so a copy never
// writes into the lender's memory; moving keeps them borrowed.
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

namespace tessera {

class VoxelStorage {
 public:
  VoxelStorage() = default;
  VoxelStorage(std::span<std::byte> borrowed, std::shared_ptr<const void> lender)
      : borrowed_(borrowed), lender_(std::move(lender)) {}
  VoxelStorage(const VoxelStorage& other) : owned_(other.bytes().begin(), other.bytes().end()) {}
  VoxelStorage& operator=(const VoxelStorage& other) {
    if (this != &other) {
      owned_.assign(other.bytes().begin(), other.bytes().end());
      borrowed_ = {};
      lender_.reset();
    }
    return *this;
  }
  VoxelStorage(VoxelStorage&& other) noexcept = default;
  VoxelStorage& operator=(VoxelStorage&& other) noexcept = default;

  void assign(std::size_t bytes) {
    owned_.assign(bytes, std::byte{0});
    borrowed_ = {};
    lender_.reset();
  }
  bool borrowed() const { return lender_ != nullptr; }
  bool empty() const { return bytes().empty(); }
  std::size_t size() const { return bytes().size(); }
  std::byte* data() { return bytes().data(); }
  const std::byte* data() const { return bytes().data(); }
  std::span<std::byte> bytes() { return lender_ ? borrowed_ : std::span<std::byte>(owned_); }
  std::span<const std::byte> bytes() const {
    return lender_ ? std::span<const std::byte>(borrowed_) : std::span<const std::byte>(owned_);
  }

 private:
  std::vector<std::byte> owned_;
  std::span<std::byte> borrowed_;
  std::shared_ptr<const void> lender_;
};

}  // namespace tessera
