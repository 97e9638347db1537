#pragma once
// A DICOMweb client (PS3.18): QIDO-RS to list studies and series, WADO-RS
// to read one series as a volume: its metadata (application/dicom+json)
// gives the slices' headers, which the folder reader's series code
// (io/DicomSeries.cpp) assembles with the same checks, geometry and rescale;
// its frames (multipart/related, `transfer-syntax=*` so that the archive
// sends what it stores) are decoded by the frame decoders of the file
// readers (DCMTK for JPEG, JPEG-LS and RLE, OpenJPEG for JPEG 2000).
//
// Requests go through HttpStorage's libcurl pool: parallel (TESSERA_HTTP_
// CONNECTIONS), with its timeouts and retries; every answer's size is
// bounded before it is held (a frame by its rows x columns x bits), and
// every error is one line naming the URL. Credentials: the value of
// TESSERA_DICOMWEB_AUTH is sent as the Authorization header ("Basic ...",
// "Bearer ..."), and DicomWebOptions::headers (the CLI's --header) are sent
// as given; neither is ever printed or logged.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tessera/core/Volume.h"
#include "tessera/io/DicomSeriesReader.h"

namespace tessera {

class HttpStorage;
namespace io_detail {
struct FolderScan;
}

// A series URL: ROOT/studies/STUDY/series/SERIES (a trailing slash allowed).
struct DicomWebSeriesUrl {
  std::string root;  // the service root, e.g. http://host:8042/dicom-web
  std::string study;
  std::string series;
};
// True for an http(s) URL whose path ends in /studies/UID/series/UID.
bool isDicomWebSeriesUrl(const std::string& spec);
// InputError naming `url` when it is not such a URL.
DicomWebSeriesUrl parseDicomWebSeriesUrl(const std::string& url);

struct DicomWebOptions {
  // Request headers "Name: value", sent with every request.
  std::vector<std::string> headers;
  // The defaults plus TESSERA_DICOMWEB_AUTH as "Authorization: <value>".
  static DicomWebOptions fromEnvironment();
};

struct DicomWebStudy {
  std::string uid;
  std::string patientName;
  std::string patientId;
  std::string date;  // YYYYMMDD as stored
  std::string description;
  std::string modalities;  // "CT\MR"
  long series = -1;        // -1: not given by the server
  long instances = -1;
};

struct DicomWebSeries {
  std::string studyUid;
  std::string uid;
  std::string modality;
  std::string description;
  long number = -1;
  long instances = -1;
  std::string url;  // ROOT/studies/STUDY/series/SERIES: what info/render/convert read
};

// What one read cost, for reports and benchmarks.
struct DicomWebTransfer {
  std::uint64_t bytes = 0;  // body bytes received, every request and attempt
  std::uint64_t requests = 0;
  std::uint64_t retries = 0;
  std::vector<std::string>
      transferSyntaxes;  // of the frames received, e.g. "1.2.840.10008.1.2.4.90"
  // Instances retrieved whole (application/dicom) because the archive did
  // not send their frames alone (Orthanc 1.10 and HTJ2K).
  std::uint64_t wholeInstances = 0;
};

class DicomWebClient {
 public:
  explicit DicomWebClient(std::string root,
                          DicomWebOptions options = DicomWebOptions::fromEnvironment());
  ~DicomWebClient();
  DicomWebClient(const DicomWebClient&) = delete;
  DicomWebClient& operator=(const DicomWebClient&) = delete;

  const std::string& root() const { return root_; }

  // QIDO-RS: the studies (`query` is appended as is, e.g.
  // "PatientName=DOE*"), and the series of one study.
  std::vector<DicomWebStudy> studies(const std::string& query = "") const;
  std::vector<DicomWebSeries> series(const std::string& studyUid) const;

  // WADO-RS: the series as one volume, as readDicomSeries reads a folder of
  // its files (same voxels and affine); InputError naming the URL at fault.
  // A series of several stacks (a multi-frame object's Stack IDs or
  // orientations) gives its largest unless `stack` names one; an unknown
  // stack is an InputError listing the stacks.
  Volume readSeries(const std::string& studyUid, const std::string& seriesUid,
                    const std::string& stack = "") const;
  // The series' stacks (one entry with stack "" when it has one), from its
  // metadata alone: what `info` lists and `--series UID:stack` selects.
  std::vector<DicomSeriesInfo> stacks(const std::string& studyUid,
                                      const std::string& seriesUid) const;

  DicomWebTransfer transfer() const;

 private:
  io_detail::FolderScan scanSeries(const std::string& seriesUrl) const;

  std::string root_;
  DicomWebOptions options_;
  std::unique_ptr<HttpStorage> http_;
  mutable std::vector<std::string> syntaxes_;
  mutable std::uint64_t probeBytes_ = 0;  // the single-attempt first request's
  mutable std::uint64_t probeRequests_ = 0;
  mutable std::uint64_t wholeInstances_ = 0;
};

// A series URL read as readVolume reads a folder; `transfer`, when given,
// receives what the read cost. `selection` is what --series takes for a
// folder: "" or the URL's series UID (its largest stack), or "UID:stack".
Volume readDicomWebSeries(const std::string& url, DicomWebTransfer* transfer = nullptr,
                          const std::string& selection = "");

// The stack `selection` names ("" for the largest); InputError naming the
// URL when it names another series than the URL's.
std::string dicomWebStack(const std::string& url, const std::string& selection);

// The stacks of a series URL, the largest first, each with the --series
// value that selects it (DicomSeriesInfo::selector).
std::vector<DicomSeriesInfo> listDicomWebSeries(const std::string& url);

}  // namespace tessera
