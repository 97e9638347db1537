// Opening a store by name (folder or URL) and reading it as one in-core
// volume: the part of the OME-Zarr reader that knows about libcurl and the
// terminal. ZarrStore itself sees only ZarrStorage, so a browser build can
// feed it from a fetch()-filled storage without this file.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/DicomWeb.h"
#include "tessera/io/HttpStorage.h"
#include "tessera/io/ZarrStore.h"

namespace tessera {

bool isZarrStore(const std::string& spec) {
  if (isHttpUrl(spec)) return !isDicomWebSeriesUrl(spec);
  std::error_code ec;
  const std::filesystem::path p(spec);
  if (!std::filesystem::is_directory(p, ec)) return false;
  for (const char* key : {".zgroup", ".zattrs", ".zarray", "zarr.json"}) {
    if (std::filesystem::is_regular_file(p / key, ec)) return true;
  }
  return false;
}

std::shared_ptr<const ZarrStorage> openZarrStorage(const std::string& spec) {
  if (isHttpUrl(spec)) return std::make_shared<HttpStorage>(spec);
  return std::make_shared<FolderStorage>(spec);
}

Volume readZarrVolume(const std::string& spec, ZarrSelection selection, std::string* chosenNote) {
  const ZarrStore store(openZarrStorage(spec), selection);
  const int l = store.finestLevelInHostBudget(spec);
  const std::uint64_t budget = HostBudget::global().limitBytes();
  // A level of many chunks (over HTTP: many requests) shows its progress
  // on a terminal.
  const bool tty = ::isatty(2) != 0;
  const auto t0 = std::chrono::steady_clock::now();
  Volume v = store.readLevel(l, [&](std::size_t done, std::size_t total) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (tty && total >= 64 && (done % 16 == 0 || done == total)) {
      std::fprintf(stderr, "\rreading %s level %d: %zu/%zu chunks  %.1f s%s", spec.c_str(), l, done,
                   total, s, done == total ? "\n" : "");
    }
  });
  const ZarrLevel& lv = store.level(l);
  const std::string dims =
      std::to_string(lv.dims.x) + "x" + std::to_string(lv.dims.y) + "x" + std::to_string(lv.dims.z);
  v.setDescription(store.describe() + ", level " + std::to_string(l) + " (" + dims + ")");
  if (chosenNote) {
    *chosenNote =
        l == 0 ? "read level 0 (" + dims + "), the finest of " + std::to_string(store.levelCount())
               : "read level " + std::to_string(l) + " (" + dims + ") of " +
                     std::to_string(store.levelCount()) +
                     ": the finest that fits the host budget " + formatBytes(budget);
    for (const std::string& n : store.notes()) *chosenNote += "; " + n;
    if (const auto* http = dynamic_cast<const HttpStorage*>(&store.storage())) {
      *chosenNote += "; fetched " + formatBytes(http->bytesFetched()) + " in " +
                     std::to_string(http->requests()) + " requests (" +
                     std::to_string(http->retries()) + " retried)";
    }
  }
  return v;
}

}  // namespace tessera
