#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/fuzz_*.cpp) with clang-14, ASan and UBSan
# into build-asan-clang/ (scripts/asan-build.sh, the build scripts/sanitize.sh
# tests in), then fuzzes each for SECONDS (default 20), two at a time when
# there are two cores or more.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     e.g. scripts/fuzz.sh 600 nifti nrrd
#
# Seeds: fuzz/corpus/<target>/ plus the matching bad-input corpus files
# (tests/data/bad/...), copied into a temporary working corpus so that the
# repository is not modified. Crash, timeout, leak and OOM inputs are saved in
# fuzz/crashes/<target>/; the script exits non-zero if any appear. Copy each
# into tests/data/bad/fuzz-regressions/<target>/ and list it in
# scripts/make_bad_corpus.py (FUZZ_REGRESSIONS) once the bug is fixed.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
SECS=${1:-20}
[ $# -gt 0 ] && shift
ALL=(nifti nrrd metaimage vti pvm raw_sidecar dicom dicom_basic transfer_function device_profile zarr zarr_v3 zarr_shard_index dicomweb htj2k functional_groups)
if [ $# -gt 0 ]; then TARGETS=("$@"); else TARGETS=("${ALL[@]}"); fi
JOBS=$(nproc)
PARALLEL=$((JOBS >= 2 ? 2 : 1))

WORK=$(mktemp -d "${TMPDIR:-/tmp}/tessera-fuzz.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
if ! scripts/asan-build.sh fuzz_targets >"$WORK/build.log" 2>&1; then
  grep -E -A5 "error|Error" "$WORK/build.log" | head -60 >&2
  echo "fuzz: building the fuzz targets failed" >&2
  exit 1
fi
for t in "${TARGETS[@]}"; do
  [ -x "build-asan-clang/fuzz_$t" ] || { echo "fuzz: build-asan-clang/fuzz_$t was not built" >&2; exit 1; }
done

# Seeds for a target: its valid files, the bad corpus of its format, and the
# crash inputs already turned into regression cases.
seed() {
  local t=$1 dir=$WORK/corpus-$t bad=tests/data/bad
  mkdir -p "$dir"
  cp fuzz/corpus/"$t"/* "$dir"/ 2>/dev/null || true
  local pattern
  case $t in
    nifti) pattern="$bad/nifti/*" ;;
    nrrd) pattern="$bad/nrrd/*.nrrd" ;;
    metaimage) pattern="$bad/metaimage/*.mha" ;;
    vti) pattern="$bad/vti/*.vti" ;;
    pvm) pattern="$bad/pvm/*.pvm" ;;
    raw_sidecar) pattern="$bad/raw/*.json" ;;
    dicom | dicom_basic) pattern="$bad/dicom/*/*" ;;
    dicomweb) pattern="$bad/dicomweb/*" ;;
    *) pattern="" ;;
  esac
  local i=0 f regressions=()
  [ -d "$bad/fuzz-regressions/$t" ] && mapfile -t regressions < <(find "$bad/fuzz-regressions/$t" -type f)
  for f in $pattern "${regressions[@]}"; do
    [ -f "$f" ] || continue
    # Bombs are kept out: each run would inflate 50 MiB for no new coverage.
    case $f in *bomb-real*) continue ;; esac
    cp "$f" "$dir/bad-$((i++))-$(basename "$f")"
  done
}

run() {
  local t=$1 crashes=$ROOT/fuzz/crashes/$t
  mkdir -p "$crashes"
  local dict=()
  [ -f "fuzz/dict/$t.dict" ] && dict=("-dict=fuzz/dict/$t.dict")
  local rc=0
  "build-asan-clang/fuzz_$t" "$WORK/corpus-$t" "${dict[@]}" -max_total_time="$SECS" -max_len=65536 \
    -timeout=5 -rss_limit_mb=1024 -print_final_stats=1 -artifact_prefix="$crashes/" \
    >"$WORK/log-$t" 2>&1 || rc=$?
  echo "$rc" >"$WORK/rc-$t"
  rmdir "$crashes" 2>/dev/null || true
}

for t in "${TARGETS[@]}"; do seed "$t"; done
echo "fuzz: ${#TARGETS[@]} targets, ${SECS} s each, $PARALLEL at a time"
running=0
for t in "${TARGETS[@]}"; do
  if [ "$running" -ge "$PARALLEL" ]; then
    wait -n
    running=$((running - 1))
  fi
  run "$t" &
  running=$((running + 1))
done
wait
rmdir fuzz/crashes 2>/dev/null || true

final_stat() { grep -m1 "^stat::$2:" "$1" | awk '{print $2}'; }
failed=0
total_runs=0
for t in "${TARGETS[@]}"; do
  log=$WORK/log-$t
  runs=$(final_stat "$log" number_of_executed_units)
  rate=$(final_stat "$log" average_exec_per_sec)
  rss=$(final_stat "$log" peak_rss_mb)
  rc=$(cat "$WORK/rc-$t")
  found=0
  [ -d "fuzz/crashes/$t" ] && found=$(find "fuzz/crashes/$t" -type f | wc -l)
  printf 'fuzz_%-18s %9s runs %6s exec/s  peak %4s MB  crashes %d\n' \
    "$t" "${runs:-?}" "${rate:-?}" "${rss:-?}" "$found"
  total_runs=$((total_runs + ${runs:-0}))
  if [ "$found" -gt 0 ] || [ "$rc" -ne 0 ]; then
    failed=1
    echo "---- fuzz_$t exited with $rc; from its log:"
    grep -E "ERROR|what\(\)|runtime error|SUMMARY|terminate|in tessera::|LLVMFuzzerTestOneInput|Dcm" \
      "$log" | cut -c1-240 | head -30
    [ "$found" -gt 0 ] && find "fuzz/crashes/$t" -type f -printf '     saved %p\n'
  fi
done
echo "fuzz: $total_runs runs in all"
if [ "$failed" -ne 0 ]; then
  echo "fuzz: FAILED: reproduce with build-asan-clang/fuzz_<target> <file>" >&2
  exit 1
fi
