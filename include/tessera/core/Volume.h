#pragma once
// A regular scalar volume in host memory: the one result of every reader and
// procedural source, and the input of every layout.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "tessera/core/ScalarType.h"
#include "tessera/core/VoxelStorage.h"

namespace tessera {

// Closed interval of raw voxel values.
struct ValueRange {
  double min = 0.0;
  double max = 1.0;
  double width() const { return max - min; }
};

class Volume {
 public:
  Volume() = default;

  // Allocates zeroed storage for dims.x*dims.y*dims.z voxels of `type`,
  // after checking the size against HostBudget::global(). `what` names the
  // volume in error messages (usually the file name).
  static Volume allocate(glm::ivec3 dims, ScalarType type, const std::string& what = "volume");

  // A volume's shape without voxels (for planning what a volume of these
  // dims and type would need): hasData() is false, value access is invalid.
  static Volume shapeOnly(glm::ivec3 dims, ScalarType type);
  // A volume over voxels another owner holds (x fastest, then y, then z),
  // not copied: `lender` keeps them alive while this volume (or a move of
  // it) lives; a copy of the volume owns a copy of them. InputError unless
  // `voxels` holds exactly dims of `type`. The Python module's from_array.
  static Volume borrow(glm::ivec3 dims, ScalarType type, std::span<std::byte> voxels,
                       std::shared_ptr<const void> lender, const std::string& what = "array");
  bool hasData() const { return !data_.empty(); }
  // The voxels are another owner's (borrow()).
  bool borrowsVoxels() const { return data_.borrowed(); }

  glm::ivec3 dims() const { return dims_; }
  glm::dvec3 spacing() const { return spacing_; }
  // World position (RAS+ mm, see core/PatientFrame.h) of voxel (0,0,0)'s centre.
  glm::dvec3 origin() const { return origin_; }
  // Unit world directions of the index axes (columns); identity = RAS storage.
  const glm::dmat3& direction() const { return direction_; }
  ScalarType type() const { return type_; }
  std::uint64_t voxelCount() const;
  std::uint64_t byteSize() const { return data_.size(); }

  // Physical extent of the volume: dims * spacing. Renderers work in the
  // volume's model frame: a box of this size centred at the origin with its
  // axes along the index axes; Camera::frame(volume) places the camera in
  // that frame from its patient-space (world) angles.
  glm::dvec3 extent() const { return glm::dvec3(dims_) * spacing_; }

  // The full index -> world affine of voxel centres:
  // world = direction * diag(spacing) * index + origin.
  glm::dmat4 indexToWorld() const;
  glm::dvec3 worldOf(glm::dvec3 index) const;
  // World position of the volume's centre (the camera's orbit centre).
  glm::dvec3 worldCentre() const;
  // Decomposes an affine into spacing (column lengths), direction (unit
  // columns) and origin. Throws InputError if it is singular or not finite.
  void setIndexToWorld(const glm::dmat4& affine);
  // Throws InputError unless the columns are finite and independent; they
  // are normalised to unit length.
  void setDirection(const glm::dmat3& direction);
  // Where the geometry came from, for `info` ("NIfTI sform (code 4, MNI)").
  const std::string& geometrySource() const { return geometrySource_; }
  void setGeometrySource(std::string s) { geometrySource_ = std::move(s); }

  // Throws InputError if any spacing component is not finite and > 0.
  void setSpacing(glm::dvec3 spacing);
  void setOrigin(glm::dvec3 origin) { origin_ = origin; }

  std::span<std::byte> bytes() { return data_.bytes(); }
  std::span<const std::byte> bytes() const { return data_.bytes(); }
  template <class T>
  T* dataAs() {
    return reinterpret_cast<T*>(data_.data());
  }
  template <class T>
  const T* dataAs() const {
    return reinterpret_cast<const T*>(data_.data());
  }

  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * dims_.y + y) * dims_.x + x;
  }
  // Raw value of a voxel as double (no window applied).
  double valueAt(int x, int y, int z) const;
  double valueAtIndex(std::size_t i) const;
  void setValueAtIndex(std::size_t i, double v);

  // Min/max of the raw values; computed on first use after data changes
  // (call invalidateRange() after writing through bytes()/dataAs()).
  ValueRange valueRange() const;
  void invalidateRange() { rangeValid_ = false; }
  // A shape without voxels (a streamed source's shape()) has the range its
  // metadata declares; without one, [0, 255] for u8 and [0, 1] otherwise.
  // Throws InputError for a non-finite or reversed range; ignored once
  // voxels are written (invalidateRange()).
  void setValueRange(ValueRange r);

  // NaN and +-Inf voxels (f32 only; 0 for integer types): every renderer,
  // the reference and the layouts read them as `nonFiniteValue()`, the
  // bottom of the value range, which every TF preset maps to opacity 0, so
  // missing data is transparent and all paths agree on it.
  std::uint64_t nonFiniteCount() const;
  double nonFiniteValue() const { return valueRange().min; }
  // valueAtIndex with non-finite values replaced by nonFiniteValue().
  double finiteValueAtIndex(std::size_t i) const;

  // The value window maps raw values to [0,1] for classification
  // (n = clamp((v - min) / (max - min), 0, 1)). Defaults to valueRange().
  ValueRange window() const;
  void setWindow(ValueRange w);
  void resetWindow() { hasWindow_ = false; }
  bool hasWindow() const { return hasWindow_; }

  // Free-form description kept for `tessera info` (source file, generator).
  const std::string& description() const { return description_; }
  void setDescription(std::string d) { description_ = std::move(d); }
  // DICOM Modality (0008,0060) as the series says it ("CT", "MR", "PT"...);
  // empty when unknown (every other format). Picks the session's default
  // transfer function (session/ModalityDefault.h).
  const std::string& modality() const { return modality_; }
  void setModality(std::string m) { modality_ = std::move(m); }

 private:
  glm::ivec3 dims_{0, 0, 0};
  glm::dvec3 spacing_{1.0, 1.0, 1.0};
  glm::dvec3 origin_{0.0, 0.0, 0.0};
  glm::dmat3 direction_{1.0};
  std::string geometrySource_;
  ScalarType type_ = ScalarType::U8;
  VoxelStorage data_;
  mutable ValueRange range_;
  mutable bool rangeValid_ = false;
  ValueRange window_;
  bool hasWindow_ = false;
  std::string description_;
  std::string modality_;
};

}  // namespace tessera
