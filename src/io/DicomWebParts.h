#pragma once
// What a DICOMweb answer holds, parsed without trusting it: multipart/related
// bodies (RFC 2046 5.1, PS3.18 8.7.3.3) split into parts that point into the
// body (nothing copied), and DICOM JSON (PS3.18 F.2) read as the attributes
// the series code reads. Every error is an InputError "WHAT: ..." in one line.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/DicomSeries.h"

namespace tessera::io_detail {

// A media type's parameter (`boundary`, `type`, `transfer-syntax`), quoted or
// not, compared without case; nullopt when absent. Quoted values keep the
// ';' they hold: type="image/jp2; transfer-syntax=1.2.840.10008.1.2.4.90".
std::optional<std::string> mediaParameter(std::string_view contentType, std::string_view name);
// The type/subtype alone, lower case: "multipart/related".
std::string mediaType(std::string_view contentType);

struct MultipartPart {
  std::string contentType;  // the part's Content-Type header ("" if none)
  std::span<const std::byte> body;
};

// Splits a multipart body by the boundary of `contentType`. InputError when
// the content type is not multipart or has no boundary, when the body does
// not start with the boundary or ends without the close delimiter, when a
// part's headers do not end, when a part's Content-Length disagrees with its
// body, or when it has more than `maxParts` parts.
std::vector<MultipartPart> parseMultipart(std::string_view contentType,
                                          std::span<const std::byte> body, const std::string& what,
                                          std::size_t maxParts);

// The transfer syntax of a frame part: its `transfer-syntax` parameter, else
// the default of its media type (PS3.18 table 8.7.3-5); "" when neither.
std::string frameTransferSyntax(std::string_view partContentType);

// Arrays and objects nested deeper than this are refused before parsing:
// DICOM JSON nests three levels per sequence, and the series code reads no
// deeper than kMaxSequenceNesting.
inline constexpr int kMaxJsonNesting = 3 * kMaxSequenceNesting + 2;

// A DICOM JSON answer: an array of datasets (objects). InputError naming
// `what` for text that is not JSON (with the parser's position), nested too
// deep, or not an array of objects.
nlohmann::json parseDicomJson(std::span<const std::byte> body, const std::string& what);

// One DICOM JSON dataset as the series code reads attributes: "Value"s
// joined with '\' as DICOM text holds them (numbers written so that they
// read back to the same double), PN as its Alphabetic group.
class DicomJsonAttributes final : public DicomAttributes {
 public:
  explicit DicomJsonAttributes(const nlohmann::json& dataset) : dataset_(dataset) {}
  std::optional<std::string> text(DicomTag tag) const override;
  std::optional<int> uint16(DicomTag tag) const override;
  std::vector<std::unique_ptr<DicomAttributes>> items(DicomTag sequence) const override;
  // Whether the element is present (with or without a value).
  bool has(DicomTag tag) const;

 private:
  const nlohmann::json* element(DicomTag tag) const;
  const nlohmann::json& dataset_;
};

}  // namespace tessera::io_detail
