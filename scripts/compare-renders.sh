#!/usr/bin/env bash
# Renders the same CLI cases with two tessera binaries and checks that the
# PNGs are byte-identical: the guard for refactorings that must not change
# images. Usage: scripts/compare-renders.sh OLD_TESSERA NEW_TESSERA [WORKDIR]
set -euo pipefail
old=$1 new=$2
work=${3:-$(mktemp -d)}
mkdir -p "$work"
ch2=/usr/share/mricron/templates/ch2.nii.gz
aal=/usr/share/mricron/templates/aal.nii.gz
store="$work/ch2.ome.zarr"
[ -d "$store" ] || "$old" convert "$ch2" "$store" --chunk 64 >/dev/null
cases=(
  "raycast-default|$ch2"
  "raycast-mip|$ch2 --mode mip --azimuth 30"
  "raycast-minip|$ch2 --mode minip"
  "raycast-average|$ch2 --mode average --elevation 20"
  "raycast-shade|$ch2 --shade --tf bench"
  "raycast-shade-precomputed|$ch2 --shade --gradient precomputed --azimuth 60"
  "raycast-preint|$ch2 --preintegrate on --step 1"
  "raycast-plain|$ch2 --preintegrate off --adaptive off --step 0.7"
  "raycast-clip|$ch2 --clip 0,1,0,0 --crop 0:1,0:0.8,0:1"
  "raycast-window|$ch2 --window 40 120 --tf grey"
  "mosaic|$ch2 --layout mosaic"
  "packed-mosaic|$ch2 --layout packed-mosaic --profile ipad2"
  "gles2-webgl1|$ch2 --profile webgl1"
  "bricks-incore|$ch2 --layout bricks"
  "fcc|gen:marschner-lobb:32 --lattice fcc --tf bench"
  "slice3d|$ch2 --technique slice3d"
  "slice2d-pre|$ch2 --technique slice2d --classify pre --azimuth 20"
  "slice2d-gles2|$ch2 --technique slice2d --profile gles2"
  "labels|$aal --labels --azimuth 90"
  "store-incore|$store --tf grey"
  "store-bricks|$store --layout bricks --azimuth 45"
  "store-region|$store --region 40:120,40:140,40:120"
  "file-region-level|$ch2 --region 10:80,10:90,10:80 --level 1"
  "streamed-head|head:256x256x256 --layout bricks --size 256x256"
  "hybrid-overlays|$ch2 --overlays box,axes --offscreen 0.5"
  "ortho-zoom|$ch2 --ortho --zoom 1.5 --background 0.2 0.2 0.3"
)
same=0 differ=0
for c in "${cases[@]}"; do
  name=${c%%|*} args=${c#*|}
  # shellcheck disable=SC2086
  "$old" render $args --out "$work/$name.old.png" >/dev/null 2>"$work/$name.old.err" || { echo "old failed: $name"; cat "$work/$name.old.err"; }
  # shellcheck disable=SC2086
  "$new" render $args --out "$work/$name.new.png" >/dev/null 2>"$work/$name.new.err" || { echo "new failed: $name"; cat "$work/$name.new.err"; }
  if cmp -s "$work/$name.old.png" "$work/$name.new.png"; then
    same=$((same + 1)); echo "identical  $name"
  else
    differ=$((differ + 1)); echo "DIFFERENT  $name"
  fi
done
echo "compare-renders: $same identical, $differ different of ${#cases[@]} cases ($work)"
[ "$differ" -eq 0 ]
