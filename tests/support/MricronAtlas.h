#pragma once
// ch2 (the MNI single-subject T1) and aal (its label atlas, with the region
// names), from Debian's mricron-data: the anatomy and overlay of the fusion
// tests; and a suite sharing ch2 written as an OME-Zarr store.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>

#include "support/TestSupport.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/io/ZarrWriter.h"
#include "tessera/session/Session.h"

namespace tessera::test {

inline const char* const kCh2 = "/usr/share/mricron/templates/ch2.nii.gz";
inline const char* const kAal = "/usr/share/mricron/templates/aal.nii.gz";
inline const char* const kAalNames = "/usr/share/mricron/templates/aal.nii.txt";

inline bool haveMricron() {
  return std::filesystem::exists(kCh2) && std::filesystem::exists(kAal) &&
         std::filesystem::exists(kAalNames);
}

// aal as a label overlay, coloured and named by its table.
inline session::OverlayOptions aalLabels(double opacity = 0.6) {
  session::OverlayOptions o;
  o.labels = true;
  o.labelTable = kAalNames;
  o.opacity = opacity;
  return o;
}

// The tests of a suite deriving from this share ch2 written as an OME-Zarr
// store (store()), made once for the suite; without mricron-data they skip.
class Ch2StoreSuite : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    if (!haveMricron()) return;
    dir() = std::make_unique<TempDir>();
    store() = (*dir() / "ch2.ome.zarr").string();
    writeOmeZarr(readVolume(kCh2), store());
  }
  static void TearDownTestSuite() { dir().reset(); }
  void SetUp() override {
    if (!haveMricron()) GTEST_SKIP() << "mricron templates not installed";
  }

 protected:
  static std::string& store() {
    static std::string path;
    return path;
  }

 private:
  static std::unique_ptr<TempDir>& dir() {
    static std::unique_ptr<TempDir> d;
    return d;
  }
};

}  // namespace tessera::test
