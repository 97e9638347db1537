// tessera formats [--markdown | --web-accept]: the format table of
// io/FormatRegistry.h, which docs/formats.md and frontends/web/index.html's file
// picker are checked against (tests/app/FormatsCommandTest.cpp).
#include <cstdio>
#include <memory>

#include "cli/Commands.h"
#include "tessera/io/DicomDecoder.h"
#include "tessera/io/FormatRegistry.h"

namespace tessera::app {

namespace {

struct FormatsOptions {
  bool markdown = false;
  bool webAccept = false;
};

void runFormats(const FormatsOptions& o) {
  if (o.webAccept) {
    std::printf("%s\n", browserAcceptList().c_str());
    return;
  }
  std::printf("%s", formatsTable(o.markdown).c_str());
  if (o.markdown) return;
  std::printf("\nDICOM decoders, preferred first:\n");
  for (const DicomDecoder* d : dicomDecoders()) {
    std::printf("  %-6s %s\n", d->name().c_str(), d->decodes().c_str());
  }
}

}  // namespace

void addFormatsCommand(CLI::App& app) {
  auto o = std::make_shared<FormatsOptions>();
  CLI::App* cmd = app.add_subcommand(
      "formats",
      "List the volume formats: extensions read and written, how the content is recognised "
      "when the name does not say, what a conversion to each loses, the native libraries each "
      "needs, and whether the web viewer reads it");
  cmd->add_flag("--markdown", o->markdown, "Print the table of docs/formats.md");
  cmd->add_flag("--web-accept", o->webAccept,
                "Print the web page's file picker accept list (the browser-readable files)");
  cmd->callback([o] { runFormats(*o); });
}

}  // namespace tessera::app
