// `tessera info --json` on the mricron-data atlases (MNI space, LAS storage,
// sform != qform) prints nibabel's img.affine: the geometry's acceptance.
// Skipped when mricron-data is not installed.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/Nibabel.h"
#include "support/TestSupport.h"

namespace fs = std::filesystem;
using tessera::test::runCli;

namespace {

const fs::path kTemplates = "/usr/share/mricron/templates";

struct Atlas {
  const char* file;
  // nibabel 5's img.affine (sform, code 2) as its 3 rows, for hosts without
  // nibabel; checked against nibabel itself where it is installed.
  double rows[3][4];
};

const Atlas kAtlases[] = {
    {"AICHAmc.nii.gz", {{-2, 0, 0, 90}, {0, 2, 0, -126}, {0, 0, 2, -72}}},
    {"HarvardOxford-cort-maxprob-thr0-1mm.nii.gz",
     {{-1, 0, 0, 90}, {0, 1, 0, -126}, {0, 0, 1, -72}}},
    {"natbrainlab.nii.gz", {{-1, 0, 0, 78}, {0, 1, 0, -112}, {0, 0, 1, -50}}},
    {"jhu189.nii.gz", {{-1, 0, 0, 78}, {0, 1, 0, -112}, {0, 0, 1, -50}}},
};

void expectRowsNear(const nlohmann::json& actual, const nlohmann::json& expected, double tol,
                    const std::string& what) {
  ASSERT_EQ(actual.size(), 4u) << what;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(actual[r][c].get<double>(), expected[r][c].get<double>(), tol)
          << what << " row " << r << " column " << c;
    }
  }
}

}  // namespace

TEST(AtlasGeometryCommand, InfoPrintsNibabelsAffineForTheMricronAtlases) {
  if (!fs::exists(kTemplates / kAtlases[0].file)) {
    GTEST_SKIP() << kTemplates << " has no atlases (mricron-data is not installed)";
  }
  const tessera::test::TempDir dir;
  nlohmann::json fromNibabel;
  if (!tessera::test::nibabelMissing()) {
    fromNibabel = nlohmann::json::parse(tessera::test::runPython(
        dir, R"PY(
import json, sys
import nibabel as nib
print(json.dumps({f: nib.load(sys.argv[1] + '/' + f).affine.tolist() for f in sys.argv[2:]}))
)PY",
        kTemplates.string() + " AICHAmc.nii.gz HarvardOxford-cort-maxprob-thr0-1mm.nii.gz "
                              "natbrainlab.nii.gz jhu189.nii.gz"));
  }
  for (const Atlas& atlas : kAtlases) {
    SCOPED_TRACE(atlas.file);
    const auto run = runCli("info " + (kTemplates / atlas.file).string() + " --json");
    ASSERT_EQ(run.exitCode, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    nlohmann::json expected = nlohmann::json::array();
    for (const auto& row : atlas.rows) expected.push_back({row[0], row[1], row[2], row[3]});
    expected.push_back({0, 0, 0, 1});
    expectRowsNear(j["affine"], expected, 1e-4, "recorded nibabel affine");
    if (!fromNibabel.is_null()) {
      expectRowsNear(j["affine"], fromNibabel[atlas.file], 1e-4, "nibabel's img.affine");
    }
    EXPECT_EQ(j["orientation"], "LAS");
    // The sform (code 2), not the qform these atlases also carry.
    EXPECT_EQ(j["geometry_source"], "NIfTI sform (code 2: aligned)");
  }
}
