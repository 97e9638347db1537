#include "support/TestSupport.h"
#include "tessera/core/Volume.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"

namespace tessera {
namespace {

using test::BudgetOverride;
using test::TempDir;

TEST(Volume, AllocateRefusesWhatExceedsTheHostBudget) {
  const std::uint64_t before = HostBudget::global().limitBytes();
  {
    BudgetOverride budget(1000);
    // 16^3 u16 = 8192 bytes > 1000.
    try {
      Volume::allocate({16, 16, 16}, ScalarType::U16, "big.nii");
      FAIL() << "expected BudgetError";
    } catch (const BudgetError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("big.nii"), std::string::npos) << msg;
      EXPECT_NE(msg.find("16x16x16 u16"), std::string::npos) << msg;
      EXPECT_NE(msg.find("8 KiB"), std::string::npos) << msg;   // what it needs
      EXPECT_NE(msg.find("1000 B"), std::string::npos) << msg;  // the budget
    }
    // Exactly at the budget is allowed: 10x10x10 u8 = 1000 bytes.
    const Volume fits = Volume::allocate({10, 10, 10}, ScalarType::U8);
    EXPECT_EQ(fits.byteSize(), 1000u);
    EXPECT_THROW(Volume::allocate({10, 10, 10}, ScalarType::F32), BudgetError);  // 4000 B
  }
  EXPECT_EQ(HostBudget::global().limitBytes(), before);
}

TEST(Volume, AllocateRejectsNonPositiveDimensions) {
  EXPECT_THROW(Volume::allocate({0, 4, 4}, ScalarType::U8), InputError);
  EXPECT_THROW(Volume::allocate({4, -1, 4}, ScalarType::U8), InputError);
  EXPECT_THROW(Volume::allocate({4, 4, (1 << 20) + 1}, ScalarType::U8), InputError);
}

TEST(Volume, AllocateZeroesStorageOfTheRightSize) {
  const Volume v = Volume::allocate({3, 4, 5}, ScalarType::I16);
  EXPECT_EQ(v.voxelCount(), 60u);
  EXPECT_EQ(v.byteSize(), 120u);
  EXPECT_EQ(v.index(2, 3, 4), 59u);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) EXPECT_EQ(v.valueAtIndex(i), 0.0);
}

TEST(Volume, ValueRangePerScalarType) {
  Volume u8 = Volume::allocate({4, 1, 1}, ScalarType::U8);
  u8.setValueAtIndex(0, 7);
  u8.setValueAtIndex(1, 200);
  u8.setValueAtIndex(2, 9);
  u8.setValueAtIndex(3, 8);
  EXPECT_EQ(u8.valueRange().min, 7.0);
  EXPECT_EQ(u8.valueRange().max, 200.0);

  Volume u16 = Volume::allocate({3, 1, 1}, ScalarType::U16);
  u16.setValueAtIndex(0, 65535);
  u16.setValueAtIndex(1, 1000);
  u16.setValueAtIndex(2, 300);
  EXPECT_EQ(u16.valueRange().min, 300.0);
  EXPECT_EQ(u16.valueRange().max, 65535.0);

  Volume i16 = Volume::allocate({3, 1, 1}, ScalarType::I16);
  i16.setValueAtIndex(0, -1024);
  i16.setValueAtIndex(1, 3071);
  i16.setValueAtIndex(2, -32768);
  EXPECT_EQ(i16.valueRange().min, -32768.0);
  EXPECT_EQ(i16.valueRange().max, 3071.0);

  Volume f32 = Volume::allocate({5, 1, 1}, ScalarType::F32);
  f32.setValueAtIndex(0, -0.25);
  f32.setValueAtIndex(1, std::numeric_limits<double>::quiet_NaN());
  f32.setValueAtIndex(2, 1.5);
  f32.setValueAtIndex(3, std::numeric_limits<double>::infinity());
  f32.setValueAtIndex(4, 0.75);
  EXPECT_EQ(f32.valueRange().min, -0.25);  // NaN and Inf do not define the range
  EXPECT_EQ(f32.valueRange().max, 1.5);
}

TEST(Volume, ValueRangeFollowsWritesAndInvalidate) {
  Volume v = Volume::allocate({2, 2, 1}, ScalarType::U8);
  EXPECT_EQ(v.valueRange().max, 0.0);
  v.setValueAtIndex(3, 42);  // setValueAtIndex invalidates by itself
  EXPECT_EQ(v.valueRange().max, 42.0);
  v.dataAs<std::uint8_t>()[0] = 99;  // a raw write needs invalidateRange()
  EXPECT_EQ(v.valueRange().max, 42.0);
  v.invalidateRange();
  EXPECT_EQ(v.valueRange().max, 99.0);
}

TEST(Volume, SetValueSaturatesAndRoundsIntegerTypes) {
  Volume u8 = Volume::allocate({6, 1, 1}, ScalarType::U8);
  u8.setValueAtIndex(0, 300);
  u8.setValueAtIndex(1, -5);
  u8.setValueAtIndex(2, 1e30);  // beyond `long`: must still saturate at 255
  u8.setValueAtIndex(3, -std::numeric_limits<double>::infinity());
  u8.setValueAtIndex(4, 12.6);
  u8.setValueAtIndex(5, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(u8.valueAtIndex(0), 255.0);
  EXPECT_EQ(u8.valueAtIndex(1), 0.0);
  EXPECT_EQ(u8.valueAtIndex(2), 255.0);
  EXPECT_EQ(u8.valueAtIndex(3), 0.0);
  EXPECT_EQ(u8.valueAtIndex(4), 13.0);
  EXPECT_EQ(u8.valueAtIndex(5), 0.0);

  Volume u16 = Volume::allocate({2, 1, 1}, ScalarType::U16);
  u16.setValueAtIndex(0, 1e20);
  u16.setValueAtIndex(1, 70000);
  EXPECT_EQ(u16.valueAtIndex(0), 65535.0);
  EXPECT_EQ(u16.valueAtIndex(1), 65535.0);

  Volume i16 = Volume::allocate({3, 1, 1}, ScalarType::I16);
  i16.setValueAtIndex(0, -1e30);
  i16.setValueAtIndex(1, std::numeric_limits<double>::infinity());
  i16.setValueAtIndex(2, -2.5);  // lround: halfway rounds away from zero
  EXPECT_EQ(i16.valueAtIndex(0), -32768.0);
  EXPECT_EQ(i16.valueAtIndex(1), 32767.0);
  EXPECT_EQ(i16.valueAtIndex(2), -3.0);
}

TEST(Volume, WindowDefaultsToTheRangeAndRejectsEmptyOrNonFiniteWindows) {
  Volume v = Volume::allocate({2, 1, 1}, ScalarType::I16);
  v.setValueAtIndex(0, -100);
  v.setValueAtIndex(1, 300);
  EXPECT_FALSE(v.hasWindow());
  EXPECT_EQ(v.window().min, -100.0);
  EXPECT_EQ(v.window().max, 300.0);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(v.setWindow({5.0, 5.0}), InputError);
  EXPECT_THROW(v.setWindow({6.0, 5.0}), InputError);
  EXPECT_THROW(v.setWindow({nan, 5.0}), InputError);
  EXPECT_THROW(v.setWindow({0.0, inf}), InputError);
  EXPECT_FALSE(v.hasWindow());  // a rejected window changes nothing

  v.setWindow({0.0, 80.0});
  EXPECT_TRUE(v.hasWindow());
  EXPECT_EQ(v.window().min, 0.0);
  EXPECT_EQ(v.window().max, 80.0);
  v.resetWindow();
  EXPECT_EQ(v.window().max, 300.0);

  // A constant volume still gets a non-empty default window.
  const Volume flat = Volume::allocate({2, 2, 2}, ScalarType::U8);
  EXPECT_EQ(flat.window().min, 0.0);
  EXPECT_EQ(flat.window().max, 1.0);
}

TEST(Volume, SetSpacingRejectsZeroNegativeAndNonFinite) {
  Volume v = Volume::allocate({10, 20, 30}, ScalarType::U8);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const glm::dvec3 bad : {glm::dvec3(0.0, 1.0, 1.0), glm::dvec3(1.0, -0.5, 1.0),
                               glm::dvec3(1.0, 1.0, nan), glm::dvec3(inf, 1.0, 1.0)}) {
    try {
      v.setSpacing(bad);
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("spacing"), std::string::npos) << e.what();
    }
    EXPECT_EQ(v.spacing(), glm::dvec3(1.0));  // unchanged
  }
  v.setSpacing({0.5, 1.0, 2.5});
  EXPECT_EQ(v.spacing(), glm::dvec3(0.5, 1.0, 2.5));
  EXPECT_EQ(v.extent(), glm::dvec3(5.0, 20.0, 75.0));
}

TEST(HostBudget, FormatsBytesForMessages) {
  EXPECT_EQ(formatBytes(17), "17 B");
  EXPECT_EQ(formatBytes(12 * 1024), "12 KiB");
  EXPECT_EQ(formatBytes(200ull << 20), "200 MiB");
  EXPECT_EQ(formatBytes(3ull << 29), "1.5 GiB");
}

// Volume::borrow (the Python module's from_array): the voxels are the
// lender's memory, kept alive by it; a copy owns a copy; a move stays borrowed.
TEST(Volume, BorrowUsesTheLendersMemoryAndACopyOwnsACopy) {
  auto lender = std::make_shared<std::vector<std::uint16_t>>(4 * 3 * 2, 7);
  (*lender)[5] = 900;
  std::span<std::byte> bytes(reinterpret_cast<std::byte*>(lender->data()), lender->size() * 2);
  Volume v = Volume::borrow({4, 3, 2}, ScalarType::U16, bytes, lender);
  std::weak_ptr<std::vector<std::uint16_t>> alive = lender;
  lender.reset();
  ASSERT_FALSE(alive.expired());  // the volume keeps its lender
  EXPECT_TRUE(v.borrowsVoxels());
  EXPECT_EQ(v.bytes().data(), bytes.data());
  EXPECT_EQ(v.byteSize(), 48u);
  EXPECT_EQ(v.valueRange().max, 900.0);
  EXPECT_EQ(v.valueAt(1, 1, 0), 900.0);

  Volume copy = v;
  EXPECT_FALSE(copy.borrowsVoxels());
  EXPECT_NE(copy.bytes().data(), bytes.data());
  copy.setValueAtIndex(5, 1.0);
  EXPECT_EQ(v.valueAt(1, 1, 0), 900.0);  // the lender's memory is untouched

  Volume moved = std::move(v);
  EXPECT_TRUE(moved.borrowsVoxels());
  EXPECT_EQ(moved.bytes().data(), bytes.data());
  moved = Volume();
  EXPECT_TRUE(alive.expired());  // released with the last volume holding it
}

TEST(Volume, BorrowRejectsABufferOfAnotherSize) {
  auto lender = std::make_shared<std::vector<std::byte>>(10);
  try {
    Volume::borrow({2, 2, 2}, ScalarType::U16, *lender, lender, "scan");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "scan: 2x2x2 u16 needs 16 bytes, the buffer has 10");
  }
}

}  // namespace
}  // namespace tessera
