#pragma once
// DICOM image files whose sequences nest `depth` levels deep, built byte by
// byte (elements PS3.5 7.1, sequences and items 7.5, UN of undefined length
// 6.2.2, deflate A.5, Part 10 PS3.10 7.1), for the tests of the readers'
// nesting limit. The image is 4x4 unsigned 16-bit, pixel i = 10 * i + 1,
// at Image Position (0, 0, z); the nested sequences are Referenced Series
// Sequences (0008,1115) in one another, the innermost item holding a Series
// Instance UID. Every level costs 36 bytes in explicit VR with undefined
// lengths: 6,000 levels are 216 KB, 100,000 levels 3.6 MB.

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/Deflate.h"

namespace tessera::test {

enum class NestedEncoding {
  ExplicitUndefined,  // explicit VR little endian, undefined lengths
  ExplicitDefined,    // explicit VR little endian, defined lengths
  ImplicitUndefined,  // implicit VR little endian (SQ from the data dictionary)
  ImplicitDefined,
  UnknownVr,  // the outer sequence written as UN, the rest implicit inside it
  BigEndian,  // explicit VR big endian, undefined lengths
  Deflated,   // deflated explicit VR little endian, undefined lengths
};

struct NestedDicomOptions {
  int depth = 1;
  NestedEncoding encoding = NestedEncoding::ExplicitUndefined;
  bool part10 = true;  // false: the bare dataset, no preamble or meta information
  std::string seriesUid = "1.2.826.0.1.3680043.10.1234.77";
  double z = 0.0;
};

inline constexpr int kNestedImageSide = 4;

inline std::uint16_t nestedImagePixel(int i) {
  return static_cast<std::uint16_t>(10 * i + 1);
}

namespace nested_detail {

class Encoder {
 public:
  Encoder(bool implicitVr, bool bigEndian) : implicit_(implicitVr), big_(bigEndian) {}

  void u16(std::uint32_t v) {
    const char a = static_cast<char>(v & 0xff);
    const char b = static_cast<char>((v >> 8) & 0xff);
    out += big_ ? std::string{b, a} : std::string{a, b};
  }
  void u32(std::uint32_t v) {
    if (big_) {
      u16(v >> 16);
      u16(v & 0xffff);
    } else {
      u16(v & 0xffff);
      u16(v >> 16);
    }
  }
  void tag(std::uint16_t group, std::uint16_t element) {
    u16(group);
    u16(element);
  }
  // Tag, VR and length (PS3.5 7.1.1-7.1.3).
  void header(std::uint16_t group, std::uint16_t element, const std::string& vr,
              std::uint32_t length) {
    tag(group, element);
    if (implicit_) {
      u32(length);
      return;
    }
    out += vr;
    if (vr == "OB" || vr == "OW" || vr == "SQ" || vr == "UN" || vr == "UT") {
      u16(0);
      u32(length);
    } else {
      u16(length);
    }
  }
  void text(std::uint16_t group, std::uint16_t element, const std::string& vr, std::string value) {
    if (value.size() % 2 != 0) value += vr == "UI" ? '\0' : ' ';
    header(group, element, vr, static_cast<std::uint32_t>(value.size()));
    out += value;
  }
  void us(std::uint16_t group, std::uint16_t element, std::uint16_t value) {
    header(group, element, "US", 2);
    u16(value);
  }
  void item(std::uint16_t element, std::uint32_t length) {
    tag(0xfffe, element);
    u32(length);
  }

  std::string out;

 private:
  bool implicit_;
  bool big_;
};

inline std::string deflateRaw(const std::string& in) {
  return deflateBytes(in, -MAX_WBITS, 9);
}

// The nested sequences: `depth` Referenced Series Sequences, one item each.
inline void nest(Encoder& e, int depth, bool defined, bool unknownOuter) {
  if (unknownOuter) {
    // The outer level as UN of undefined length: inside it, implicit VR
    // little endian (CP-246), undefined lengths.
    e.header(0x0008, 0x1115, "UN", 0xffffffffu);
    Encoder in(true, false);
    in.item(0xe000, 0xffffffffu);
    nest(in, depth - 1, false, false);
    in.item(0xe00d, 0);
    in.item(0xe0dd, 0);
    e.out += in.out;
    return;
  }
  // What the innermost item holds, and a sequence header's size, encoded
  // as the levels are.
  Encoder innermost = e;
  innermost.out.clear();
  innermost.text(0x0020, 0x000e, "UI", "1.2.826.0.1.3680043.10.1234.78");
  Encoder probe = innermost;
  probe.out.clear();
  probe.header(0x0008, 0x1115, "SQ", 0);
  const std::uint32_t itemHeader = 8;
  const auto seqHeader = static_cast<std::uint32_t>(probe.out.size());
  const auto content = static_cast<std::uint32_t>(innermost.out.size());
  for (int level = 0; level < depth; ++level) {
    if (defined) {
      // The sequence at `level` (0: outermost) holds one item, which holds
      // the levels below it.
      const auto below = static_cast<std::uint32_t>(depth - 1 - level);
      const std::uint32_t length = below * (itemHeader + seqHeader) + itemHeader + content;
      e.header(0x0008, 0x1115, "SQ", length);
      e.item(0xe000, length - itemHeader);
    } else {
      e.header(0x0008, 0x1115, "SQ", 0xffffffffu);
      e.item(0xe000, 0xffffffffu);
    }
  }
  e.out += innermost.out;
  if (!defined) {
    for (int level = 0; level < depth; ++level) {
      e.item(0xe00d, 0);
      e.item(0xe0dd, 0);
    }
  }
}

}  // namespace nested_detail

inline std::string nestedDicomFile(const NestedDicomOptions& o) {
  using nested_detail::Encoder;
  const NestedEncoding enc = o.encoding;
  const bool implicitVr =
      enc == NestedEncoding::ImplicitUndefined || enc == NestedEncoding::ImplicitDefined;
  const bool big = enc == NestedEncoding::BigEndian;
  const char* syntax = implicitVr                        ? "1.2.840.10008.1.2"
                       : big                             ? "1.2.840.10008.1.2.2"
                       : enc == NestedEncoding::Deflated ? "1.2.840.10008.1.2.1.99"
                                                         : "1.2.840.10008.1.2.1";
  const std::string sopClass = "1.2.840.10008.5.1.4.1.1.7";  // Secondary Capture
  const std::string sop = "1.2.826.0.1.3680043.10.1234.79." + std::to_string(o.depth);

  Encoder d(implicitVr, big);
  d.text(0x0008, 0x0016, "UI", sopClass);
  d.text(0x0008, 0x0018, "UI", sop);
  d.text(0x0008, 0x0060, "CS", "OT");
  nested_detail::nest(
      d, o.depth, enc == NestedEncoding::ExplicitDefined || enc == NestedEncoding::ImplicitDefined,
      enc == NestedEncoding::UnknownVr);
  d.text(0x0020, 0x000e, "UI", o.seriesUid);
  d.text(0x0020, 0x0013, "IS", "1");
  char position[64];
  std::snprintf(position, sizeof position, "0\\0\\%g", o.z);
  d.text(0x0020, 0x0032, "DS", position);
  d.text(0x0020, 0x0037, "DS", "1\\0\\0\\0\\1\\0");
  d.us(0x0028, 0x0002, 1);
  d.text(0x0028, 0x0004, "CS", "MONOCHROME2");
  d.us(0x0028, 0x0010, kNestedImageSide);
  d.us(0x0028, 0x0011, kNestedImageSide);
  d.text(0x0028, 0x0030, "DS", "1\\1");
  d.us(0x0028, 0x0100, 16);
  d.us(0x0028, 0x0101, 16);
  d.us(0x0028, 0x0102, 15);
  d.us(0x0028, 0x0103, 0);
  d.header(0x7fe0, 0x0010, "OW", 2 * kNestedImageSide * kNestedImageSide);
  for (int i = 0; i < kNestedImageSide * kNestedImageSide; ++i) d.u16(nestedImagePixel(i));
  if (!o.part10) return d.out;

  Encoder meta(false, false);  // always explicit VR little endian
  meta.text(0x0002, 0x0001, "OB", std::string("\0\1", 2));
  meta.text(0x0002, 0x0002, "UI", sopClass);
  meta.text(0x0002, 0x0003, "UI", sop);
  meta.text(0x0002, 0x0010, "UI", syntax);
  meta.text(0x0002, 0x0012, "UI", "1.2.826.0.1.3680043.10.1234.99");
  Encoder groupLength(false, false);
  groupLength.header(0x0002, 0x0000, "UL", 4);
  groupLength.u32(static_cast<std::uint32_t>(meta.out.size()));
  const std::string dataset =
      enc == NestedEncoding::Deflated ? nested_detail::deflateRaw(d.out) : d.out;
  std::string file(128, '\0');  // the preamble
  file.append("DICM").append(groupLength.out).append(meta.out).append(dataset);
  return file;
}

}  // namespace tessera::test
