// tessera dicomweb URL: the studies of a DICOMweb service (QIDO-RS) and the
// series of each, with the series URLs that info, render and convert read.
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/io/DicomWeb.h"

namespace tessera::app {

namespace {

struct DicomWebListOptions {
  std::string url;
  std::vector<std::string> headers;
  std::string patient;
  bool json = false;
};

// ROOT, or ROOT/studies/UID: the service root and the study it names.
void splitStudy(const std::string& url, std::string& root, std::string& study) {
  root = url;
  while (!root.empty() && root.back() == '/') root.pop_back();
  const auto at = root.rfind("/studies/");
  if (at != std::string::npos && root.find('/', at + 9) == std::string::npos) {
    study = root.substr(at + 9);
    root.resize(at);
  }
}

std::string count(long n) {
  return n < 0 ? "?" : std::to_string(n);
}

nlohmann::json seriesJson(const DicomWebSeries& s) {
  return {{"uid", s.uid},
          {"number", s.number},
          {"modality", s.modality},
          {"description", s.description},
          {"instances", s.instances},
          {"url", s.url}};
}

void runDicomWeb(const DicomWebListOptions& o) {
  if (isDicomWebSeriesUrl(o.url)) {
    throw InputError(o.url +
                     ": a series URL; `tessera info URL` describes it, `tessera dicomweb ROOT` "
                     "lists the studies");
  }
  std::string root;
  std::string study;
  splitStudy(o.url, root, study);
  DicomWebOptions options = DicomWebOptions::fromEnvironment();
  options.headers.insert(options.headers.end(), o.headers.begin(), o.headers.end());
  const DicomWebClient client(root, options);
  std::vector<DicomWebStudy> studies;
  if (study.empty()) {
    studies = client.studies(o.patient.empty() ? "" : "PatientName=" + o.patient);
  } else {
    studies = client.studies("StudyInstanceUID=" + study);
    if (studies.empty()) throw InputError(o.url + ": no such study on this server");
  }
  nlohmann::json out = nlohmann::json::array();
  for (const DicomWebStudy& st : studies) {
    const std::vector<DicomWebSeries> series = client.series(st.uid);
    if (o.json) {
      nlohmann::json js = nlohmann::json::array();
      for (const auto& s : series) js.push_back(seriesJson(s));
      out.push_back({{"uid", st.uid},
                     {"patientName", st.patientName},
                     {"patientId", st.patientId},
                     {"date", st.date},
                     {"description", st.description},
                     {"modalities", st.modalities},
                     {"instances", st.instances},
                     {"series", js}});
      continue;
    }
    std::printf(
        "study %s\n  patient %s (ID %s), date %s, %s, modalities %s, %s series, %s "
        "instances\n",
        st.uid.c_str(), st.patientName.c_str(), st.patientId.c_str(), st.date.c_str(),
        st.description.empty() ? "no description" : ("'" + st.description + "'").c_str(),
        st.modalities.c_str(), count(st.series).c_str(), count(st.instances).c_str());
    std::printf("  %-4s %-4s %9s  %-24s %s\n", "#", "mod", "instances", "description", "URL");
    for (const auto& s : series) {
      std::printf("  %-4s %-4s %9s  %-24s %s\n", count(s.number).c_str(), s.modality.c_str(),
                  count(s.instances).c_str(), s.description.substr(0, 24).c_str(), s.url.c_str());
    }
  }
  if (o.json) {
    std::printf("%s\n", nlohmann::json{{"root", root}, {"studies", out}}.dump(2).c_str());
  } else if (studies.empty()) {
    std::printf("no studies at %s\n", root.c_str());
  }
}

}  // namespace

void addDicomWebCommand(CLI::App& app) {
  auto o = std::make_shared<DicomWebListOptions>();
  CLI::App* cmd = app.add_subcommand(
      "dicomweb",
      "List the studies and series of a DICOMweb service (QIDO-RS): patient, date, description, "
      "modality, instance counts and each series' URL, which info, render and convert read "
      "(ROOT/studies/UID/series/UID). Credentials: TESSERA_DICOMWEB_AUTH (the Authorization "
      "header's value) or --header; never printed");
  cmd->add_option("url", o->url,
                  "Service root (e.g. http://host:8042/dicom-web), or ROOT/studies/UID")
      ->required();
  cmd->add_option("--header", o->headers, "Request header 'Name: value' (repeatable)");
  cmd->add_option("--patient", o->patient,
                  "Only studies whose Patient's Name matches (QIDO: * wildcards)");
  cmd->add_flag("--json", o->json, "Print JSON instead of the table");
  cmd->callback([o] { runDicomWeb(*o); });
}

}  // namespace tessera::app
