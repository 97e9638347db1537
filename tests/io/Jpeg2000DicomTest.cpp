// DICOM frames in JPEG 2000 (OpenJPEG), read through readVolume like any
// DICOM file: lossless streams give the uncompressed original's voxels
// exactly, a lossy one OpenJPEG's own command-line decode, and a corrupt or
// mis-sized frame one line naming the file. An HTJ2K codestream in a file
// that says JPEG 2000 is decoded by OpenJPH (Debian 12's OpenJPEG aborts on
// corrupt HTJ2K data). The streams are
// pydicom's test files and ones encoded here with Debian's encoders
// (opj_compress, ojph_compress), wrapped in DICOM by pydicom.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "io/IoFixtures.h"
#include "support/ExpectError.h"
#include "support/SourceScan.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/VolumeReader.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPython = "/usr/bin/python3";
const fs::path kPydicomFiles = "/usr/lib/python3/dist-packages/pydicom/data/test_files";

bool have(const std::string& command) {
  return std::system((command + " >/dev/null 2>&1").c_str()) == 0;
}

bool pydicomReady() {
  return have(std::string(kPython) + " -c 'import pydicom, numpy'") &&
         fs::exists(kPydicomFiles / "MR_small.dcm");
}

// `file` copied alone into its own folder of `dir` and read: a named file
// reads its series from the files beside it, so each is kept apart.
Volume readAlone(const fs::path& dir, const fs::path& file) {
  const fs::path folder = dir / (file.filename().string() + ".d");
  fs::create_directories(folder);
  fs::copy_file(file, folder / file.filename(), fs::copy_options::overwrite_existing);
  return readVolume((folder / file.filename()).string());
}

void expectSameVoxels(const Volume& a, const Volume& b) {
  ASSERT_EQ(a.dims(), b.dims());
  ASSERT_EQ(a.type(), b.type());
  ASSERT_EQ(a.bytes().size(), b.bytes().size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.voxelCount(); ++i) {
    differing += a.valueAtIndex(i) != b.valueAtIndex(i) ? 1 : 0;
  }
  EXPECT_EQ(differing, 0u) << "of " << a.voxelCount() << " voxels";
}

// Writes `name`.dcm: MR_small.dcm's header and pixels, the pixels encoded by
// `encode` ("htj2k-lossless", "htj2k-lossy", "j2k-lossless") into one
// fragment, with the matching transfer syntax.
const char* kWrap = R"py(
import subprocess, sys
import numpy as np
import pydicom
from pydicom._uid_dict import UID_dictionary
from pydicom.encaps import encapsulate
# pydicom 2.3 predates HTJ2K: its transfer syntaxes are made known to it.
for uid, name in (('1.2.840.10008.1.2.4.201', 'HTJ2KLossless'), ('1.2.840.10008.1.2.4.203', 'HTJ2K')):
    UID_dictionary.setdefault(uid, (name, 'Transfer Syntax', '', '', name))
src, out, kind, work = sys.argv[1:5]
d = pydicom.dcmread(src)
a = d.pixel_array.astype(np.int16)
raw = work + '/frame.raw'
a.astype('<i2').tofile(raw)
rows, cols = a.shape
if kind.startswith('htj2k'):  # htj2k-in-j2k-syntax: an HTJ2K stream in a file saying .90
    stream = work + '/frame.j2c'
    args = ['ojph_compress', '-i', raw, '-o', stream, '-dims', '{%d,%d}' % (cols, rows),
            '-num_comps', '1', '-signed', 'true', '-bit_depth', '16', '-downsamp', '{1,1}']
    args += ['-reversible', 'true'] if kind != 'htj2k-lossy' else ['-qstep', '0.0002']
    uid = '1.2.840.10008.1.2.4.201' if kind == 'htj2k-lossless' else '1.2.840.10008.1.2.4.203'
    if kind == 'htj2k-in-j2k-syntax':
        uid = '1.2.840.10008.1.2.4.90'
else:
    # MR_small's values are positive: an unsigned 16-bit PGM carries them.
    stream = work + '/frame.j2k'
    pgm = work + '/frame.pgm'
    with open(pgm, 'wb') as f:
        f.write(b'P5\n%d %d\n65535\n' % (cols, rows))
        f.write(a.astype('>u2').tobytes())
    args = ['opj_compress', '-i', pgm, '-o', stream]
    uid = '1.2.840.10008.1.2.4.90'
subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
data = open(stream, 'rb').read()
d.file_meta.TransferSyntaxUID = uid
d.is_little_endian, d.is_implicit_VR = True, False
d.PixelData = encapsulate([data])
d['PixelData'].VR = 'OB'
d['PixelData'].is_undefined_length = True
d.save_as(out, write_like_original=False)
)py";

TEST(Jpeg2000Dicom, PydicomsLosslessJpeg2000EqualsTheUncompressedOriginal) {
  if (!pydicomReady()) GTEST_SKIP() << "needs python3-pydicom's test files and numpy";
  test::TempDir dir;
  const Volume original = readAlone(dir.path(), kPydicomFiles / "MR_small.dcm");
  const Volume j2k = readAlone(dir.path(), kPydicomFiles / "MR_small_jp2klossless.dcm");
  expectSameVoxels(j2k, original);
  EXPECT_EQ(j2k.spacing(), original.spacing());
  EXPECT_EQ(j2k.origin(), original.origin());
  EXPECT_EQ(j2k.direction(), original.direction());  // the patient's left stays left
  EXPECT_EQ(j2k.indexToWorld(), original.indexToWorld());
}

TEST(Jpeg2000Dicom, Jpeg2000AndHtj2kEncodedHereReadBackExactly) {
  if (!pydicomReady()) GTEST_SKIP() << "needs python3-pydicom's test files and numpy";
  if (!have("command -v ojph_compress") || !have("command -v opj_compress")) {
    GTEST_SKIP() << "needs ojph_compress (openjph-tools) and opj_compress (libopenjp2-tools)";
  }
  test::TempDir dir;
  test::writeFile(dir.path() / "wrap.py", kWrap);
  const Volume original = readAlone(dir.path(), kPydicomFiles / "MR_small.dcm");
  // HTJ2K in a file that says JPEG 2000 goes to OpenJPH too (by its CAP
  // marker); Htj2kDicomTest covers the HTJ2K syntaxes themselves.
  for (const std::string kind : {"j2k-lossless", "htj2k-lossless", "htj2k-in-j2k-syntax"}) {
    SCOPED_TRACE(kind);
    const fs::path work = dir.path() / kind;
    fs::create_directories(work);
    const fs::path out = work / (kind + ".dcm");
    ASSERT_TRUE(have(std::string(kPython) + " " + (dir.path() / "wrap.py").string() + " " +
                     (kPydicomFiles / "MR_small.dcm").string() + " " + out.string() + " " + kind +
                     " " + work.string()));
    expectSameVoxels(readVolume(out.string()), original);
  }
}

// A lossy JPEG 2000 CT slice (pydicom's 693_J2KI.dcm): each stored value is
// what OpenJPEG's command-line decoder makes of the same codestream.
TEST(Jpeg2000Dicom, LossyJpeg2000EqualsOpenJpegsOwnDecode) {
  if (!pydicomReady()) GTEST_SKIP() << "needs python3-pydicom's test files and numpy";
  if (!have("command -v opj_decompress")) GTEST_SKIP() << "needs opj_decompress";
  test::TempDir dir;
  const fs::path file = kPydicomFiles / "693_J2KI.dcm";
  test::writeFile(dir.path() / "decode.py", R"py(
import subprocess, sys
import numpy as np
import pydicom
from pydicom.encaps import generate_pixel_data_frame
d = pydicom.dcmread(sys.argv[1])
frame = next(generate_pixel_data_frame(d.PixelData))
open(sys.argv[2] + '/f.j2k', 'wb').write(frame)
subprocess.run(['opj_decompress', '-i', sys.argv[2] + '/f.j2k', '-o', sys.argv[2] + '/f.pgx'],
               check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
import glob
pgx = sorted(glob.glob(sys.argv[2] + '/f*.pgx'))[0]
raw = open(pgx, 'rb').read()
header, data = raw.split(b'\n', 1)
parts = header.split()
signed = parts[2] == b'-' or parts[2].startswith(b'-')
dt = ('>' if parts[1] == b'ML' else '<') + ('i2' if signed else 'u2')
a = np.frombuffer(data[:int(parts[-1]) * int(parts[-2]) * 2], dtype=dt).astype(np.float64)
a = a * float(getattr(d, 'RescaleSlope', 1)) + float(getattr(d, 'RescaleIntercept', 0))
a.astype('<f8').tofile(sys.argv[2] + '/expected.f64')
)py");
  ASSERT_TRUE(have(std::string(kPython) + " " + (dir.path() / "decode.py").string() + " " +
                   file.string() + " " + dir.path().string()));
  const Volume v = readAlone(dir.path(), file);
  const std::string expected = test::readText(dir.path() / "expected.f64");
  ASSERT_EQ(expected.size(), v.voxelCount() * sizeof(double));
  std::size_t differing = 0;
  for (std::size_t i = 0; i < v.voxelCount(); ++i) {
    double e = 0.0;
    std::memcpy(&e, expected.data() + i * sizeof(double), sizeof e);
    differing += std::abs(v.valueAtIndex(i) - e) > 1e-9 ? 1 : 0;
  }
  EXPECT_EQ(differing, 0u) << "of " << v.voxelCount();
}

// A codestream cut short, and a frame of another size than the header's
// Rows: one line naming the file, nothing read.
TEST(Jpeg2000Dicom, CorruptOrMisSizedFramesAreNamedErrors) {
  if (!pydicomReady()) GTEST_SKIP() << "needs python3-pydicom's test files and numpy";
  test::TempDir dir;
  test::writeFile(dir.path() / "break.py", R"py(
import sys
import pydicom
from pydicom.encaps import encapsulate, generate_pixel_data_frame
d = pydicom.dcmread(sys.argv[1])
frame = next(generate_pixel_data_frame(d.PixelData))
if sys.argv[3] == 'truncated':
    d.PixelData = encapsulate([frame[:len(frame) // 3]])
else:
    d.Rows = d.Rows // 2
d['PixelData'].is_undefined_length = True
d.save_as(sys.argv[2], write_like_original=False)
)py");
  for (const std::string how : {"truncated", "rows"}) {
    const fs::path folder = dir.path() / how;
    fs::create_directories(folder);
    const fs::path out = folder / ("mr-" + how + ".dcm");
    ASSERT_TRUE(have(std::string(kPython) + " " + (dir.path() / "break.py").string() + " " +
                     (kPydicomFiles / "MR_small_jp2klossless.dcm").string() + " " + out.string() +
                     " " + how));
    const std::string message = test::inputErrorMessage([&] { readVolume(out.string()); });
    EXPECT_EQ(message.rfind(out.string() + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(how == "rows" ? "but the file declares 64x32" : "cannot be decoded"),
              std::string::npos)
        << message;
  }
}

}  // namespace
}  // namespace tessera
