#!/usr/bin/env bash
# The main job for a newcomer: set up, build, render the default volume
# (the ch2 MRI head) to out/head.png and print its path and the time taken.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh --target tessera_cli
# `import tessera` for Debian's python3 (docs/python.md): a .pth naming the
# build's package folder, as `pip install -e .` would; where that folder
# cannot be written, PYTHONPATH=build/python does the same.
if [ -d build/python/tessera ]; then
  site=$(/usr/bin/python3 -c 'import site; print(site.getsitepackages()[0])')
  if mkdir -p "$site" 2>/dev/null && echo "$(pwd)/build/python" >"$site/tessera-build.pth" 2>/dev/null; then
    echo "python: import tessera works in /usr/bin/python3 ($site/tessera-build.pth -> build/python)"
  else
    echo "python: cannot write $site; use PYTHONPATH=$(pwd)/build/python"
  fi
fi
mkdir -p out
build/tessera render --out out/head.png "$@"
echo "image: $(pwd)/out/head.png"
