// DICOM geometry (IPP/IOP -> RAS affine, and back) and the defects
// found on pydicom's and nibabel's test files, each reproduced by a file
// that pydicom writes at test time (Debian's /usr/bin/python3 with
// python3-pydicom; the tests skip, saying why, when it is missing).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>

#include "io/IoFixtures.h"
#include "tessera/core/Error.h"
#include "tessera/core/PatientFrame.h"
#include "tessera/io/DicomSeriesReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPython = "/usr/bin/python3";

// Writes DICOM files described by a Python literal (a list of dicts), or
// dumps the Image Plane attributes of written files, one line per file.
constexpr const char* kGenerator = R"py(
import ast
import os
import struct
import sys

import numpy as np
from pydicom import config
from pydicom.dataelem import DataElement
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.encaps import encapsulate
from pydicom.filereader import dcmread
from pydicom.sequence import Sequence
from pydicom.uid import generate_uid

SYNTAX = {
    'explicit': '1.2.840.10008.1.2.1',
    'implicit': '1.2.840.10008.1.2',
    'deflate': '1.2.840.10008.1.2.1.99',
    'j2k': '1.2.840.10008.1.2.4.90',
}


# Keep elements stored as UN as UN (pydicom would give them their dictionary VR).
config.replace_un_with_known_vr = False


def ds(v):
    return '%.10g' % v


def as_un(d, keyword):
    """Re-stores an attribute with VR UN, as a writer that does not know it."""
    elem = d.data_element(keyword)
    if elem.VR == 'US':
        raw = struct.pack('<H', elem.value)
    else:
        values = elem.value if elem.VM > 1 else [elem.value]
        raw = '\\'.join(str(v) for v in values).encode('ascii')
        if len(raw) % 2:
            raw += b' '
    d[elem.tag] = DataElement(elem.tag, 'UN', raw)


def private_sequence():
    """A private sequence nested in itself, as pydicom's nested_priv_SQ.dcm."""
    inner = Dataset()
    inner.add_new(0x00010001, 'OB', b'Double Nested SQ')
    item = Dataset()
    item.add_new(0x00010001, 'SQ', Sequence([inner]))
    item.add_new(0x00010002, 'OB', b'Nested SQ\0')
    item[0x00010001].is_undefined_length = True
    for i in (inner, item):
        i.is_undefined_length_sequence_item = True
    return Sequence([item])


def make(spec):
    rows, cols, frames = spec.get('rows', 16), spec.get('cols', 16), spec.get('frames', 1)
    syntax = spec.get('syntax', 'explicit')
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = '1.2.840.10008.5.1.4.1.1.4'  # MR Image Storage
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = SYNTAX[syntax]
    d = Dataset()
    d.file_meta = meta
    d.is_little_endian = True
    d.is_implicit_VR = syntax == 'implicit'
    if spec.get('private_sq'):
        d.add_new(0x00010001, 'SQ', private_sequence())
        d[0x00010001].is_undefined_length = True
    d.SOPClassUID = meta.MediaStorageSOPClassUID
    d.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    d.Modality = 'MR'
    if spec.get('uid'):
        d.SeriesInstanceUID = spec['uid']
    if 'instance' in spec:
        d.InstanceNumber = spec['instance']
    if 'ipp' in spec:
        d.ImagePositionPatient = [ds(v) for v in spec['ipp']]
    if 'iop' in spec:
        d.ImageOrientationPatient = [ds(v) for v in spec['iop']]
    if 'thickness' in spec:
        d.SliceThickness = ds(spec['thickness'])
    if 'slope' in spec:
        d.RescaleSlope = ds(spec['slope'])
        d.RescaleIntercept = ds(spec['intercept'])
    if not spec.get('no_image_attrs'):
        d.SamplesPerPixel = 1
        d.PhotometricInterpretation = 'MONOCHROME2'
        if frames > 1:
            d.NumberOfFrames = frames
        d.Rows = rows
        d.Columns = cols
        d.PixelSpacing = [ds(v) for v in spec.get('ps', [1, 1])]
        d.BitsAllocated = 16
        d.BitsStored = 16
        d.HighBit = 15
        d.PixelRepresentation = spec.get('signed', 0)
    # value = base + linear index within the frame: a misplaced row or
    # column shows.
    pixels = (spec.get('base', 0) + np.arange(frames * rows * cols) % (rows * cols))
    if 'constant' in spec:
        pixels = np.full(frames * rows * cols, spec['constant'])
    data = pixels.astype('<u2').tobytes() + b'\0' * spec.get('pad', 0)
    if spec.get('no_image_attrs'):
        data = b'\0\0'
    if syntax == 'j2k':
        d.PixelData = encapsulate([bytes(range(64))])  # not a real codestream
        d['PixelData'].VR = 'OB'
        d['PixelData'].is_undefined_length = True
    else:
        d.PixelData = data
        d['PixelData'].VR = 'OW'
    for keyword in spec.get('un', []):
        as_un(d, keyword)
    d.save_as(spec['file'], write_like_original=False)
    if spec.get('truncate'):
        os.truncate(spec['file'], os.path.getsize(spec['file']) - spec['truncate'])


def dump(folder, out):
    with open(out, 'w') as f:
        for name in sorted(os.listdir(folder)):
            d = dcmread(os.path.join(folder, name))
            numbers = [d.InstanceNumber] + list(d.ImagePositionPatient) + \
                list(d.ImageOrientationPatient) + [d.SliceLocation, d.SpacingBetweenSlices]
            f.write(' '.join(repr(float(v)) for v in numbers) + '\n')


if __name__ == '__main__':
    if sys.argv[1] == 'make':
        with open(sys.argv[2]) as f:
            for spec in ast.literal_eval(f.read()):
                make(spec)
    else:
        dump(sys.argv[2], sys.argv[3])
)py";

bool havePydicom() {
  static const bool ok =
      std::system((std::string(kPython) + " -c 'import pydicom, numpy' >/dev/null 2>&1").c_str()) ==
      0;
  return ok;
}

#define REQUIRE_PYDICOM()                                                             \
  if (!havePydicom())                                                                 \
  GTEST_SKIP() << kPython << " cannot import pydicom and numpy (Debian: apt install " \
               << "python3-pydicom); these tests generate their DICOM files with it"

std::string py(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string pyVec(const double* v, int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + py(v[i]);
  return s + "]";
}

using Iop = std::array<double, 6>;
constexpr Iop kAxial = {1, 0, 0, 0, 1, 0};
constexpr Iop kSagittal = {0, 1, 0, 0, 0, -1};
constexpr Iop kCoronal = {1, 0, 0, 0, 0, -1};

// One file for the generator; `more` adds Python dict entries ("'pad': 128").
struct FileSpec {
  std::string name;
  std::optional<std::string> uid = "1.2.826.0.1.3680043.9.7.12.1";
  std::optional<int> instance;
  std::optional<glm::dvec3> ipp;
  std::optional<Iop> iop;
  glm::dvec2 ps{0.8, 0.6};  // Pixel Spacing: between rows, between columns
  int rows = 16;
  int cols = 16;
  int base = 0;  // pixel value = base + row * cols + column
  std::string more;
};

std::string literal(const test::TempDir& dir, const FileSpec& f) {
  std::string s = "{'file': '" + (dir / f.name).string() + "'";
  if (f.uid) s += ", 'uid': '" + *f.uid + "'";
  if (f.instance) s += ", 'instance': " + std::to_string(*f.instance);
  if (f.ipp) s += ", 'ipp': " + pyVec(&f.ipp->x, 3);
  if (f.iop) s += ", 'iop': " + pyVec(f.iop->data(), 6);
  s += ", 'ps': " + pyVec(&f.ps.x, 2) + ", 'rows': " + std::to_string(f.rows) +
       ", 'cols': " + std::to_string(f.cols) + ", 'base': " + std::to_string(f.base);
  if (!f.more.empty()) s += ", " + f.more;
  return s + "}";
}

std::string shellQuoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') {
      q.append("'\\''");
    } else {
      q.push_back(c);
    }
  }
  return q + "'";
}

// Writes the generator into `work` and runs Python with `args` (the first
// is the script); fails the test with Python's message.
void runGenerator(const test::TempDir& work, const std::vector<std::string>& args) {
  test::writeFile(work / "gen.py", kGenerator);
  std::string cmd = kPython;
  for (const auto& a : args) cmd.append(" ").append(shellQuoted(a));
  cmd.append(" 2>").append(shellQuoted((work / "gen.err").string()));
  if (std::system(cmd.c_str()) != 0) {
    std::ifstream err(work / "gen.err");
    std::stringstream ss;
    ss << err.rdbuf();
    FAIL() << "pydicom generator failed: " << ss.str();
  }
}

// Writes `files` with pydicom into `dir` (the generator lives in `work`).
void generate(const test::TempDir& work, const test::TempDir& dir,
              const std::vector<FileSpec>& files) {
  std::string spec = "[";
  for (const auto& f : files) spec += literal(dir, f) + ",\n";
  test::writeFile(work / "spec.txt", spec + "]");
  runGenerator(work, {(work / "gen.py").string(), "make", (work / "spec.txt").string()});
}

glm::dvec3 cross(const Iop& iop) {
  return glm::cross(glm::dvec3(iop[0], iop[1], iop[2]), glm::dvec3(iop[3], iop[4], iop[5]));
}

// The RAS affine that files with this IOP, Pixel Spacing and IPPs (in z
// order) describe, computed here from the numbers alone: columns row
// cosines x column spacing, column cosines x row spacing, the step from the
// first to the second position, translation the first position; then x and
// y negated (DICOM's LPS -> RAS).
glm::dmat4 expectedAffine(const Iop& iop, glm::dvec2 ps, const std::vector<glm::dvec3>& ipps) {
  glm::dmat4 lps(1.0);
  for (int r = 0; r < 3; ++r) {
    lps[0][r] = iop[static_cast<std::size_t>(r)] * ps.y;
    lps[1][r] = iop[static_cast<std::size_t>(r) + 3] * ps.x;
    lps[3][r] = ipps[0][r];
  }
  const glm::dvec3 step =
      ipps.size() > 1 ? ipps[1] - ipps[0] : glm::dvec3(0.0);  // single slices: set by the test
  for (int r = 0; r < 3; ++r) lps[2][r] = step[r];
  glm::dmat4 ras = lps;
  for (int c = 0; c < 4; ++c) {
    ras[c][0] = -lps[c][0];
    ras[c][1] = -lps[c][1];
  }
  return ras;
}

void expectAffineNear(const glm::dmat4& got, const glm::dmat4& want, double tolerance) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 3; ++r) {
      EXPECT_NEAR(got[c][r], want[c][r], tolerance) << "affine row " << r << ", column " << c;
    }
  }
}

// A slice `name` of orientation `iop` at `ipp`, the rest as FileSpec says.
FileSpec placedSlice(std::string name, const Iop& iop, glm::dvec3 ipp) {
  FileSpec f;
  f.name = std::move(name);
  f.iop = iop;
  f.ipp = ipp;
  return f;
}

// A stack of `n` slices: positions first + k * step, files named so that
// name order is not slice order; Instance Number k + 1 unless `numbered` is
// false; pixel base 1000 k.
std::vector<FileSpec> stack(const Iop& iop, glm::dvec3 first, glm::dvec3 step, int n,
                            bool numbered = true) {
  std::vector<FileSpec> files;
  for (int k = 0; k < n; ++k) {
    FileSpec f = placedSlice("IM" + std::to_string((k * 5 + 3) % n) + ".dcm", iop,
                             first + static_cast<double>(k) * step);
    if (numbered) f.instance = k + 1;
    f.base = 1000 * k;
    f.rows = 12;
    files.push_back(f);
  }
  return files;
}

std::vector<glm::dvec3> positions(const std::vector<FileSpec>& files) {
  std::vector<glm::dvec3> p;
  for (const auto& f : files) p.push_back(*f.ipp);
  return p;
}

// Voxel (x, y, z) must hold pixel (column x, row y) of the file with base
// bases[z]: voxels are stored as in the files.
void expectVoxelsOf(const Volume& v, const std::vector<int>& bases, int cols) {
  ASSERT_EQ(v.dims().z, static_cast<int>(bases.size()));
  int wrong = 0;
  for (int z = 0; z < v.dims().z; ++z) {
    for (int y = 0; y < v.dims().y; ++y) {
      for (int x = 0; x < v.dims().x; ++x) {
        const double want = bases[static_cast<std::size_t>(z)] + y * cols + x;
        if (v.valueAt(x, y, z) != want && wrong++ == 0) {
          ADD_FAILURE() << "voxel " << x << "," << y << "," << z << " is " << v.valueAt(x, y, z)
                        << ", expected " << want;
        }
      }
    }
  }
  EXPECT_EQ(wrong, 0);
}

std::vector<int> basesOf(const std::vector<FileSpec>& files) {
  std::vector<int> b;
  for (const auto& f : files) b.push_back(f.base);
  return b;
}

// Reads a generated stack and checks affine and voxels against `inZOrder`
// (the files in the z order expected).
Volume expectStackReads(const test::TempDir& dir, const std::vector<FileSpec>& inZOrder) {
  Volume v = readDicomSeries(dir.path());
  const FileSpec& f = inZOrder.front();
  EXPECT_EQ(v.dims(), glm::ivec3(f.cols, f.rows, static_cast<int>(inZOrder.size())));
  expectAffineNear(v.indexToWorld(), expectedAffine(*f.iop, f.ps, positions(inZOrder)), 1e-6);
  expectVoxelsOf(v, basesOf(inZOrder), f.cols);
  EXPECT_NE(v.geometrySource().find("DICOM IPP/IOP (LPS -> RAS)"), std::string::npos)
      << v.geometrySource();
  return v;
}

// Generates the stack `files` (in z order) into a folder of its own, checks
// it reads back (expectStackReads) and gives the orientation code read.
std::string stackOrientation(const test::TempDir& work, const std::vector<FileSpec>& files) {
  const test::TempDir dir;
  generate(work, dir, files);
  if (::testing::Test::HasFatalFailure()) return "(not generated)";
  return orientationOf(expectStackReads(dir, files).direction()).code;
}

TEST(DicomGeometry, AxialSeriesInEitherSliceOrderGivesTheAffineOfItsPositions) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  {
    SCOPED_TRACE("feet to head");
    EXPECT_EQ(stackOrientation(work, stack(kAxial, {-40.5, 22.25, -10}, {0, 0, 2.5}, 8)), "LPS");
  }
  {
    // A scanner going head to foot: Instance Number grows downwards, and z
    // follows it (an LPI volume, nothing flipped).
    SCOPED_TRACE("head to feet");
    EXPECT_EQ(stackOrientation(work, stack(kAxial, {-40.5, 22.25, 60}, {0, 0, -2.5}, 8)), "LPI");
  }
  {
    // Without Instance Numbers, z grows along the normal (row x column).
    SCOPED_TRACE("head to feet, no Instance Number");
    test::TempDir dir;
    auto files = stack(kAxial, {-40.5, 22.25, 60}, {0, 0, -2.5}, 8, false);
    ASSERT_NO_FATAL_FAILURE(generate(work, dir, files));
    std::reverse(files.begin(), files.end());
    expectStackReads(dir, files);
  }
}

TEST(DicomGeometry, SagittalAndCoronalSeriesGiveTheirRasAffine) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  {
    SCOPED_TRACE("sagittal");
    // IOP 0\1\0\0\0\-1: rows run posterior, columns inferior, the normal
    // (row x column) points right; the slices are numbered right to left.
    EXPECT_EQ(stackOrientation(work, stack(kSagittal, {-30, -100, 80}, {3, 0, 0}, 8)), "PIL");
  }
  {
    SCOPED_TRACE("coronal");
    // IOP 1\0\0\0\0\-1: normal = (1,0,0) x (0,0,-1) = (0,1,0), posterior.
    EXPECT_EQ(stackOrientation(work, stack(kCoronal, {-90, -20, 70}, {0, 1.5, 0}, 8)), "LIP");
  }
}

// Row and column cosines rotated 20 degrees about z, then 15 about x.
Iop obliqueIop() {
  const double a = glm::radians(20.0);
  const double b = glm::radians(15.0);
  const auto aboutX = [&](glm::dvec3 v) {
    return glm::dvec3(v.x, v.y * std::cos(b) - v.z * std::sin(b),
                      v.y * std::sin(b) + v.z * std::cos(b));
  };
  const glm::dvec3 row = aboutX({std::cos(a), std::sin(a), 0});
  const glm::dvec3 col = aboutX({-std::sin(a), std::cos(a), 0});
  return {row.x, row.y, row.z, col.x, col.y, col.z};
}

TEST(DicomGeometry, ObliqueSeriesGivesItsTrueAffine) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  const Iop iop = obliqueIop();
  const auto files = stack(iop, {12.5, -7.25, 33}, 2.0 * cross(iop), 8);
  ASSERT_NO_FATAL_FAILURE(generate(work, dir, files));
  expectStackReads(dir, files);
  const Orientation o = orientationOf(readDicomSeries(dir.path()).direction());
  EXPECT_TRUE(o.oblique);
  EXPECT_NEAR(o.shearDeg, 0.0, 1e-6);
}

TEST(DicomGeometry, GantryTiltGivesAShearedAffine) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  // 12 degrees of tilt: each slice 2.5 mm up and 2.5 tan(12 deg) mm back.
  const glm::dvec3 step(0, 2.5 * std::tan(glm::radians(12.0)), 2.5);
  const auto files = stack(kAxial, {-60, -80, -20}, step, 8);
  ASSERT_NO_FATAL_FAILURE(generate(work, dir, files));
  expectStackReads(dir, files);
  const Volume v = readDicomSeries(dir.path());
  EXPECT_NEAR(orientationOf(v.direction()).shearDeg, 12.0, 1e-6);
  EXPECT_NE(v.description().find("gantry tilt 12 deg"), std::string::npos) << v.description();
}

TEST(DicomGeometry, PositionsOffAStraightLineAreRefused) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  auto files = stack(kAxial, {0, 0, 0}, {0, 0, 2}, 6);
  files[3].ipp->x += 3.0;  // 5 pixels sideways
  ASSERT_NO_FATAL_FAILURE(generate(work, dir, files));
  test::expectRejected<InputError>([&] { readDicomSeries(dir.path()); },
                                   {files[3].name, "do not form a regular stack"});
}

TEST(DicomGeometry, SingleSliceAndMissingOrientationFallBackAsDocumented) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  {
    SCOPED_TRACE("one coronal slice with Slice Thickness");
    test::TempDir dir;
    FileSpec f = placedSlice("one.dcm", kCoronal, glm::dvec3(-90, 14, 70));
    f.more = "'thickness': 3.5";
    ASSERT_NO_FATAL_FAILURE(generate(work, dir, {f}));
    const Volume v = readDicomSeries(dir / "one.dcm");
    glm::dmat4 want = expectedAffine(kCoronal, f.ps, {*f.ipp});
    want[2] = glm::dvec4(lpsToRas() * (3.5 * cross(kCoronal)), 0);  // normal x thickness
    expectAffineNear(v.indexToWorld(), want, 1e-9);
    EXPECT_NE(v.geometrySource().find("z spacing from Slice Thickness"), std::string::npos);
  }
  {
    SCOPED_TRACE("no IOP, no IPP");
    test::TempDir dir;
    FileSpec f;
    f.name = "bare.dcm";
    ASSERT_NO_FATAL_FAILURE(generate(work, dir, {f}));
    const Volume v = readDicomSeries(dir / "bare.dcm");
    glm::dmat4 want(1.0);
    want[0][0] = -f.ps.y;  // LPS axial in RAS: x and y negated
    want[1][1] = -f.ps.x;
    expectAffineNear(v.indexToWorld(), want, 1e-12);
    EXPECT_NE(v.geometrySource().find("no Image Orientation (Patient): axial assumed"),
              std::string::npos)
        << v.geometrySource();
    EXPECT_NE(v.geometrySource().find("origin 0"), std::string::npos);
  }
}

// ---------------------------------------------------------------------------
// Writer: the affine goes out as LPS IPP/IOP and comes back.

// A 5 x 4 x 6 ramp whose index axes point along `axes` (RAS columns).
Volume volumeWithAxes(const glm::dmat3& axes) {
  Volume v = Volume::allocate({5, 4, 6}, ScalarType::U16);
  for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, static_cast<double>(i));
  v.invalidateRange();
  const glm::dvec3 spacing(0.7, 0.8, 1.5);
  glm::dmat4 affine(1.0);
  for (int c = 0; c < 3; ++c) affine[c] = glm::dvec4(axes[c] * spacing[c], 0.0);
  affine[3] = glm::dvec4(10.25, -20.5, 30.75, 1.0);
  v.setIndexToWorld(affine);
  return v;
}

glm::dmat3 columns(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  return glm::dmat3(a, b, c);
}

struct NamedAxes {
  const char* name;
  glm::dmat3 axes;
};

std::vector<NamedAxes> orientationsToWrite() {
  const double a = glm::radians(25.0);
  const double b = glm::radians(-10.0);
  const glm::dvec3 r(std::cos(a), std::sin(a), 0);
  const glm::dvec3 u(-std::sin(a) * std::cos(b), std::cos(a) * std::cos(b), std::sin(b));
  const double t = glm::radians(15.0);
  return {
      {"RAS", glm::dmat3(1.0)},
      {"LAS", columns({-1, 0, 0}, {0, 1, 0}, {0, 0, 1})},
      {"LPS", columns({-1, 0, 0}, {0, -1, 0}, {0, 0, 1})},
      {"LPI", columns({-1, 0, 0}, {0, -1, 0}, {0, 0, -1})},
      {"sagittal-PIL", columns({0, -1, 0}, {0, 0, -1}, {-1, 0, 0})},
      {"coronal-LIP", columns({-1, 0, 0}, {0, 0, -1}, {0, -1, 0})},
      {"oblique", columns(r, u, glm::cross(r, u))},
      {"gantry-tilt-15-deg", columns({1, 0, 0}, {0, 1, 0}, {0, std::sin(t), std::cos(t)})},
  };
}

// The Image Plane attributes pydicom reads from the written files, one row
// per file in name (= slice) order: instance, IPP, IOP, Slice Location,
// Spacing Between Slices.
std::vector<std::vector<double>> planeAttributes(const test::TempDir& work, const fs::path& dir) {
  const fs::path out = work / "dump.txt";
  runGenerator(work, {(work / "gen.py").string(), "dump", dir.string(), out.string()});
  std::vector<std::vector<double>> rows;
  std::ifstream in(out);
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::vector<double> row;
    for (double x; ls >> x;) row.push_back(x);
    rows.push_back(row);
  }
  return rows;
}

TEST(DicomGeometryWriter, ReadBackGivesTheAffineOfEveryOrientation) {
  test::TempDir dir;
  for (const auto& o : orientationsToWrite()) {
    SCOPED_TRACE(o.name);
    const Volume v = volumeWithAxes(o.axes);
    const fs::path out = dir / o.name;
    writeDicomSeries(v, out);
    const Volume r = readDicomSeries(out);
    EXPECT_EQ(r.dims(), v.dims());
    expectAffineNear(r.indexToWorld(), v.indexToWorld(), 1e-4);
    ASSERT_EQ(r.byteSize(), v.byteSize());
    EXPECT_TRUE(std::equal(r.bytes().begin(), r.bytes().end(), v.bytes().begin()));
  }
}

TEST(DicomGeometryWriter, PydicomReadsTheExpectedLpsPositionsAndOrientation) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  for (const auto& o : orientationsToWrite()) {
    SCOPED_TRACE(o.name);
    const Volume v = volumeWithAxes(o.axes);
    const fs::path out = dir / o.name;
    writeDicomSeries(v, out);
    std::vector<std::vector<double>> rows;
    ASSERT_NO_FATAL_FAILURE(rows = planeAttributes(work, out));
    ASSERT_EQ(rows.size(), 6u);
    // Expected, from the volume's numbers alone: RAS -> LPS negates x and y.
    const auto lps = [](glm::dvec3 p) { return glm::dvec3(-p.x, -p.y, p.z); };
    const glm::dvec3 origin(10.25, -20.5, 30.75);
    const glm::dvec3 row = lps(glm::normalize(o.axes[0]));
    const glm::dvec3 col = lps(glm::normalize(o.axes[1]));
    const glm::dvec3 normal = glm::cross(row, col);
    const glm::dvec3 step = lps(glm::normalize(o.axes[2]) * 1.5);
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& f = rows[k];
      ASSERT_EQ(f.size(), 12u);
      EXPECT_EQ(f[0], static_cast<double>(k + 1));
      const glm::dvec3 ipp = lps(origin) + static_cast<double>(k) * step;
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(f[1 + i], ipp[i], 1e-4) << "IPP of slice " << k;
        EXPECT_NEAR(f[4 + i], row[i], 1e-6) << "IOP row";
        EXPECT_NEAR(f[7 + i], col[i], 1e-6) << "IOP column";
      }
      EXPECT_NEAR(f[10], glm::dot(ipp, normal), 1e-4) << "Slice Location";
      EXPECT_NEAR(f[11], std::abs(glm::dot(step, normal)), 1e-4) << "Spacing Between Slices";
    }
  }
}

TEST(DicomGeometryWriter, QuantisationErrorIsWhatReadingBackGives) {
  test::TempDir dir;
  Volume f = Volume::allocate({10, 10, 3}, ScalarType::F32);
  for (std::size_t i = 0; i < f.voxelCount(); ++i) {
    f.setValueAtIndex(i, -3.25 + 0.0137 * static_cast<double>(i));
  }
  f.invalidateRange();
  writeDicomSeries(f, dir / "f");
  const Volume r = readDicomSeries(dir / "f");
  double measured = 0;
  for (std::size_t i = 0; i < f.voxelCount(); ++i) {
    measured = std::max(measured, std::abs(r.valueAtIndex(i) - f.valueAtIndex(i)));
  }
  const double step = (f.valueRange().max - f.valueRange().min) / 65535.0;
  EXPECT_GT(measured, 0.0);
  EXPECT_DOUBLE_EQ(dicomQuantisationError(f), measured);
  EXPECT_LE(dicomQuantisationError(f), 0.5 * step * 1.01);

  // Integers that fit are exact, in every type.
  Volume ints = Volume::allocate({4, 4, 2}, ScalarType::F32);
  for (std::size_t i = 0; i < ints.voxelCount(); ++i) ints.setValueAtIndex(i, -7.0 + i);
  ints.invalidateRange();
  EXPECT_EQ(dicomQuantisationError(ints), 0.0);
  for (ScalarType t : {ScalarType::U8, ScalarType::U16, ScalarType::I16}) {
    Volume v = Volume::allocate({4, 4, 2}, t);
    for (std::size_t i = 0; i < v.voxelCount(); ++i) v.setValueAtIndex(i, static_cast<double>(i));
    v.invalidateRange();
    EXPECT_EQ(dicomQuantisationError(v), 0.0) << scalarTypeName(t);
  }
}

// ---------------------------------------------------------------------------
// Defects found on pydicom's and nibabel's test files.

// nibabel's decimal_rescale.dcm (no Series Instance UID) reported the
// 256x256x2 series of 0.dcm and 1.dcm beside it.
TEST(DicomDefects, ANamedFileReadsItsOwnSeriesAndStack) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  auto files = stack(kAxial, {0, 0, 0}, {0, 0, 3}, 2);  // the "0.dcm, 1.dcm" series
  FileSpec lone;
  lone.name = "decimal_rescale.dcm";
  lone.uid.reset();
  lone.rows = 8;
  lone.cols = 12;
  lone.iop = Iop{1, 0, 0, 0, 0.9948807, 0.1010563};
  lone.ipp = glm::dvec3(-116.07, -97.9, -43.23);
  lone.more = "'slope': 2, 'intercept': -4096, 'thickness': 5";
  files.push_back(lone);
  // Same UID as the stack, other size: a localizer-like file.
  FileSpec other = files[0];
  other.name = "localizer.dcm";
  other.rows = 10;
  other.iop = kCoronal;
  other.base = 500;
  files.push_back(other);
  ASSERT_NO_FATAL_FAILURE(generate(work, dir, files));

  const Volume v = readDicomSeries(dir / "decimal_rescale.dcm");
  EXPECT_EQ(v.dims(), glm::ivec3(12, 8, 1));
  EXPECT_EQ(v.valueAt(3, 2, 0), 2.0 * (2 * 12 + 3) - 4096);
  EXPECT_NE(v.description().find("(no Series Instance UID) (1 slice"), std::string::npos);

  const Volume l = readDicomSeries(dir / "localizer.dcm");
  EXPECT_EQ(l.dims(), glm::ivec3(16, 10, 1));
  EXPECT_EQ(l.valueAt(0, 0, 0), 500);
  EXPECT_NE(l.description().find("left out 2 file(s) of this series"), std::string::npos)
      << l.description();

  const Volume s = readDicomSeries(dir / files[1].name);
  EXPECT_EQ(s.dims(), glm::ivec3(16, 12, 2));
}

// pydicom's MR_small.dcm beside MR_truncated.dcm (same series and position)
// and JPGExtended.dcm beside JPEG 2000 files of its series were refused
// because of the broken neighbours.
TEST(DicomDefects, UnreadableCopiesBesideAReadableFileAreSkippedAndCounted) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  {
    SCOPED_TRACE("MR_small beside MR_truncated");
    test::TempDir dir;
    FileSpec small = placedSlice("MR_small.dcm", kAxial, glm::dvec3(-83.9063, -91.2, 6.6406));
    FileSpec truncated = small;
    truncated.name = "MR_truncated.dcm";
    truncated.more = "'truncate': 62";  // ends inside its pixel data
    ASSERT_NO_FATAL_FAILURE(generate(work, dir, {small, truncated}));
    const Volume v = readDicomSeries(dir / "MR_small.dcm");
    expectVoxelsOf(v, {0}, 16);
    const std::string d = v.description();
    EXPECT_NE(d.find("skipped 1 unreadable file(s) of this series"), std::string::npos) << d;
    EXPECT_NE(d.find("MR_truncated.dcm: not a readable DICOM file"), std::string::npos) << d;
    test::expectRejected<InputError>([&] { readDicomSeries(dir / "MR_truncated.dcm"); },
                                     {"MR_truncated.dcm", "truncated"});
  }
  {
    SCOPED_TRACE("JPGExtended beside JPEG 2000 files");
    test::TempDir dir;
    FileSpec readable;
    readable.name = "JPGExtended.dcm";
    FileSpec j2k = readable;
    j2k.name = "JPEG2000.dcm";
    j2k.more = "'syntax': 'j2k', 'signed': 1";
    FileSpec j2k2 = j2k;
    j2k2.name = "JPEG2000-embedded-sequence-delimiter.dcm";
    ASSERT_NO_FATAL_FAILURE(generate(work, dir, {readable, j2k, j2k2}));
    const Volume v = readDicomSeries(dir / "JPGExtended.dcm");
    expectVoxelsOf(v, {0}, 16);
    EXPECT_NE(v.description().find("skipped 2 unreadable file(s) of this series"),
              std::string::npos)
        << v.description();
  }
  {
    SCOPED_TRACE("a truncated slice of its own is still an error");
    test::TempDir dir;
    auto files = stack(kAxial, {0, 0, 0}, {0, 0, 2}, 4);
    files[3].more = "'truncate': 62";
    ASSERT_NO_FATAL_FAILURE(generate(work, dir, files));
    test::expectRejected<InputError>([&] { readDicomSeries(dir / files[0].name); },
                                     {files[3].name, "truncated", "incomplete"});
  }
}

// pydicom's image_dfl.dcm: the inflated pixel data is larger than the file,
// which the length check took for corruption.
TEST(DicomDefects, DeflatedFileIsRead) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  FileSpec f;
  f.name = "image_dfl.dcm";
  f.rows = 64;
  f.cols = 64;
  f.more = "'syntax': 'deflate', 'constant': 7";
  ASSERT_NO_FATAL_FAILURE(generate(work, dir, {f}));
  ASSERT_LT(fs::file_size(dir / f.name), 64u * 64u * 2u);  // the condition reproduced
  const Volume v = readDicomSeries(dir / f.name);
  EXPECT_EQ(v.dims(), glm::ivec3(64, 64, 1));
  EXPECT_EQ(v.valueRange().min, 7);
  EXPECT_EQ(v.valueRange().max, 7);
  EXPECT_NE(v.description().find("1.2.840.10008.1.2.1.99"), std::string::npos);
}

// pydicom's MR_small_padded.dcm: 128 bytes after Rows x Columns pixels.
TEST(DicomDefects, TrailingPixelPaddingIsIgnored) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  FileSpec f;
  f.name = "MR_small_padded.dcm";
  f.more = "'pad': 128";
  ASSERT_NO_FATAL_FAILURE(generate(work, dir, {f}));
  const Volume v = readDicomSeries(dir / f.name);
  expectVoxelsOf(v, {0}, 16);
  EXPECT_NE(v.description().find("ignored trailing padding"), std::string::npos);
}

// pydicom's rtdose_rle.dcm stores most attributes with VR UN: the error
// showed Image Position's raw bytes in hex instead of the real reason.
TEST(DicomDefects, AttributesStoredAsUnAreReadForTheRealReason) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  // As in rtdose_rle.dcm: the Image Plane attributes are UN, Rows is US.
  const std::string un = "'un': ['ImagePositionPatient', 'ImageOrientationPatient', 'PixelSpacing'";
  {
    test::TempDir dir;
    FileSpec f = placedSlice("rtdose.dcm", kAxial, glm::dvec3(189.43125, 199.43125, -761.87));
    f.more = "'frames': 3, " + un + "]";
    ASSERT_NO_FATAL_FAILURE(generate(work, dir, {f}));
    // Classic multi-frame: three frames from the UN Image Position, 1 mm apart.
    const Volume v = readDicomSeries(dir / f.name);
    EXPECT_EQ(v.dims(), glm::ivec3(16, 16, 3));
    EXPECT_LT(glm::length(v.origin() - glm::dvec3(-189.43125, -199.43125, -761.87)), 1e-6);
  }
  {
    test::TempDir dir;
    auto files = stack(obliqueIop(), {5, 6, 7}, 2.0 * cross(obliqueIop()), 3);
    for (auto& f : files) f.more = un + ", 'Rows']";  // a UN unsigned short too
    ASSERT_NO_FATAL_FAILURE(generate(work, dir, files));
    expectStackReads(dir, files);
  }
}

// pydicom's nested_priv_SQ.dcm (pixel data, no image attributes) said
// "has no Rows Rows".
TEST(DicomDefects, MissingImageAttributesAreNamedOnceEach) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  FileSpec f;
  f.name = "nested_priv_SQ.dcm";
  f.uid.reset();
  f.more = "'syntax': 'implicit', 'no_image_attrs': True, 'private_sq': True";
  ASSERT_NO_FATAL_FAILURE(generate(work, dir, {f}));
  try {
    readDicomSeries(dir / f.name);
    ADD_FAILURE() << "read a file without Rows";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("nested_priv_SQ.dcm: has Pixel Data but no Rows (0028,0010), Columns "
                     "(0028,0011) or Bits Allocated (0028,0100)"),
              std::string::npos)
        << m;
    EXPECT_EQ(m.find("Rows Rows"), std::string::npos) << m;
    EXPECT_EQ(m.find("Rows"), m.rfind("Rows")) << m;
  }
}

// JPEG 2000 refusals carried DCMTK's "Pixel representation cannot be changed".
TEST(DicomDefects, Jpeg2000IsRefusedInOnePlainLine) {
  REQUIRE_PYDICOM();
  test::TempDir work;
  test::TempDir dir;
  FileSpec f;
  f.name = "MR_small_jp2klossless.dcm";
  f.more = "'syntax': 'j2k'";
  ASSERT_NO_FATAL_FAILURE(generate(work, dir, {f}));
  for (const fs::path& p : {dir / f.name, dir.path()}) {
    try {
      readDicomSeries(p);
      ADD_FAILURE() << "read JPEG 2000 pixels without a decoder";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find((dir / f.name).string() +
                       ": JPEG 2000 (transfer syntax UID 1.2.840.10008.1.2.4.90) is not "
                       "supported by this build"),
                std::string::npos)
          << m;
      EXPECT_NE(m.find("gdcmconv --raw"), std::string::npos) << m;
      EXPECT_EQ(m.find("DCMTK:"), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  }
}

}  // namespace
}  // namespace tessera
