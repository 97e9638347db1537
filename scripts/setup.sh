#!/usr/bin/env bash
# Installs everything Tessera needs on Debian 12 (idempotent: installs only
# what is missing). Run as root, or as a user with sudo.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git clang-format
  libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri   # headless OpenGL ES (Mesa llvmpipe)
  libnifti2-dev zlib1g-dev libpng-dev libdcmtk-dev dcmtk # volume and image I/O (DICOM: DCMTK)
  libcli11-dev nlohmann-json3-dev libglm-dev             # CLI, JSON, maths
  libgtest-dev libgmock-dev glslang-tools                # tests (glslangValidator checks GLSL ES 1.00 rules)
  clang-14 libclang-rt-14-dev                            # fuzzing: libFuzzer + sanitizers (scripts/fuzz.sh)
  mricron-data                                           # the default volume (ch2 T1 MRI head)
  libglfw3-dev libimgui-dev xvfb xauth libx11-dev        # desktop viewer (tessera view), tested under Xvfb (an X drop: Xlib)
  emscripten nodejs chromium libxtst6                    # web viewer (scripts/web.sh), its browser test (X input: XTest)
  python3-nibabel python3-pydicom python3-numpy          # independent NIfTI/DICOM readers in geometry tests
  libblosc-dev libzstd-dev libcurl4-openssl-dev          # OME-Zarr chunks (blosc, zstd) and HTTP(S) stores
  libopenjp2-7-dev                                       # DICOM frames in JPEG 2000
  libopenjph-dev                                         # DICOM frames in HTJ2K (OpenJPH)
  libopenjp2-tools openjph-tools                         # JPEG 2000 and HTJ2K encoders, for the tests' data
  python3-zarr python3-numcodecs nginx-light             # zarr-python interop tests; nginx serves stores in HTTP tests
  python3-vtk9 python3-matplotlib                        # bench/peers: VTK side by side (PNGs, plots) and its smoke tests
  orthanc orthanc-dicomweb                               # a real PACS (DICOMweb) started by the DICOMweb tests on loopback
  pybind11-dev python3-pybind11 python3-pytest           # the Python module (import tessera) and its tests
  python3-ipywidgets python3-ipykernel python3-nbclient python3-nbconvert  # Jupyter display, widget, the example notebook run headless
  python3-dask python3-distributed                       # tessera.zarr.write_pyramid on a dask cluster
)

# playwright-core for the browser test, pinned by tests/browser/package-lock.json;
# pako for the web page (its inflater), pinned by frontends/web/package-lock.json;
# zarrita for the Zarr v3 interop test, pinned by tests/interop/package-lock.json.
npm_deps() {
  local root
  root="$(cd "$(dirname "$0")/.." && pwd)"
  if [ ! -d "$root/tests/browser/node_modules/playwright-core" ]; then
    echo "setup: npm ci in tests/browser (playwright-core)"
    (cd "$root/tests/browser" && npm ci --no-audit --no-fund --loglevel=error)
  fi
  if [ ! -d "$root/tests/interop/node_modules/zarrita" ]; then
    echo "setup: npm ci in tests/interop (zarrita)"
    (cd "$root/tests/interop" && npm ci --no-audit --no-fund --loglevel=error)
  fi
  if [ ! -f "$root/frontends/web/node_modules/@cornerstonejs/dicom-image-loader/dist/esm/codecs/jpeg.js" ]; then
    echo "setup: npm ci in web (pako, numcodecs, DICOM decoders)"
    (cd "$root/frontends/web" && npm ci --no-audit --no-fund --loglevel=error)
  fi
}

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
command -v npm >/dev/null || missing+=(npm)  # nodejs from elsewhere may bring its own npm

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  npm_deps
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null; then SUDO="sudo"; else
    echo "setup: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
  fi
fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
npm_deps
