// Runs tests/interop/zarrita.test.mjs (node's test runner against npm's
// zarrita, pinned in tests/interop/package.json) with this build's CLI, so
// that ctest covers the Zarr v3 / OME-NGFF 0.5 interoperability both ways:
// every node test must pass, and the interop table must list each case.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;

std::string run(const std::string& cmd, int& status) {
  std::string out;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) {
    status = -1;
    return out;
  }
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), int(buf.size()), p)) out += buf.data();
  status = ::pclose(p);
  return out;
}

TEST(ZarritaInterop, ZarritaAndTesseraReadEachOthersV3StoresVoxelForVoxel) {
  const fs::path dir = fs::path(TESSERA_TEST_DATA_DIR).parent_path() / "interop";
  int status = 0;
  run("node --version >/dev/null 2>&1", status);
  if (status != 0) GTEST_SKIP() << "node is not installed";
  if (!fs::exists(dir / "node_modules" / "zarrita")) {
    run("cd '" + dir.string() + "' && npm ci --no-audit --no-fund >/dev/null 2>&1", status);
    if (status != 0) GTEST_SKIP() << "npm ci in " << dir << " failed (no registry?)";
  }
  const std::string out = run("cd '" + dir.string() + "' && TESSERA='" + TESSERA_CLI_PATH +
                                  "' node --test --test-reporter=spec zarrita.test.mjs 2>&1",
                              status);
  EXPECT_EQ(status, 0) << out;
  EXPECT_NE(out.find("fail 0"), std::string::npos) << out;
  // 10 zarrita-written arrays, 2 spec-built sharded stores, 5 Tessera stores.
  int rows = 0;
  for (const char* mark : {"voxels equal", "Tessera: equal"}) {
    for (std::size_t at = out.find(mark); at != std::string::npos; at = out.find(mark, at + 1)) {
      ++rows;
    }
  }
  EXPECT_GE(rows, 17) << out;
}

}  // namespace
