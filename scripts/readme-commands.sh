#!/usr/bin/env bash
# Runs every command of README.md's fenced shell blocks, so that what a
# newcomer pastes works.
#
# Convention (documented in README.md too):
#   ```sh  or  ```bash          each command in the block is run
#   ```sh skip-test             the block is shown, never run: it needs a
#                               display, serves until stopped, installs
#                               packages or runs the whole test suite
#   any other fence (```, ```json ...) is not a command block.
# A command is one line; a line ending in a backslash continues on the next.
# Comments and blank lines are left to the shell.
#
# The commands run one after another in one temporary folder (a later command
# may read what an earlier one wrote, e.g. a converted store), with `build` and
# `tests` there links to this checkout's folders: `build/tessera` is the binary
# `scripts/build.sh` made, and the images land in the temporary folder, never
# in the checkout. Each command gets at most READMECMD_TIMEOUT seconds
# (default 600).
#
# Usage: scripts/readme-commands.sh [--list] [README]
#   --list   print the commands (and the skipped blocks) without running them
# Exit status: 0 when every command succeeded; 1 naming the first that failed
# (its output is printed); 2 for a usage error or a missing binary.
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
list=0
readme="$repo/README.md"
for arg in "$@"; do
  case "$arg" in
    --list) list=1 ;;
    -h | --help)
      sed -n '2,25p' "$0" | sed 's/^# \{0,1\}//'
      exit 0
      ;;
    *) readme="$arg" ;;
  esac
done
[[ -f "$readme" ]] || { echo "readme-commands: $readme: no such file" >&2; exit 2; }

# Extract the commands: one per record, NUL-separated, "RUN<TAB>line<TAB>cmd"
# or "SKIP<TAB>line<TAB>cmd".
extract() {
  awk '
    function flush() { if (cmd != "") { printf "%s\t%d\t%s%c", mode, start, cmd, 0; cmd = "" } }
    /^```/ {
      if (!infence) {
        infence = 1
        info = substr($0, 4)
        gsub(/^[ \t]+|[ \t]+$/, "", info)
        n = split(info, words, /[ \t]+/)
        shell = (words[1] == "sh" || words[1] == "bash")
        mode = "RUN"
        for (i = 2; i <= n; i++) if (words[i] == "skip-test") mode = "SKIP"
        next
      }
      flush(); infence = 0; shell = 0; next
    }
    infence && shell {
      line = $0
      if (cmd == "") {
        if (line ~ /^[ \t]*(#.*)?$/) next
        start = NR
      }
      if (line ~ /\\$/) { cmd = cmd substr(line, 1, length(line) - 1); next }
      cmd = cmd line
      flush()
    }
  ' "$readme"
}

mapfile -d '' records < <(extract)
if ((${#records[@]} == 0)); then
  echo "readme-commands: no sh/bash blocks in $readme" >&2
  exit 2
fi

if ((list)); then
  for r in "${records[@]}"; do
    IFS=$'\t' read -r mode line cmd <<<"$r"
    printf '%-4s %s:%s  %s\n' "$mode" "$(basename "$readme")" "$line" "$cmd"
  done
  exit 0
fi

if [[ ! -x "$repo/build/tessera" ]]; then
  echo "readme-commands: $repo/build/tessera is missing: build it first (scripts/build.sh --target tessera_cli)" >&2
  exit 2
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/tessera-readme.XXXXXX")"
trap 'rm -rf "$work"' EXIT
ln -s "$repo/build" "$work/build"
ln -s "$repo/tests" "$work/tests"  # the test-data generators a command may run (tests/zarr/*.py)
timeout_s="${READMECMD_TIMEOUT:-600}"

ran=0
skipped=0
t0=$SECONDS
for r in "${records[@]}"; do
  IFS=$'\t' read -r mode line cmd <<<"$r"
  where="$(basename "$readme"):$line"
  if [[ "$mode" == SKIP ]]; then
    skipped=$((skipped + 1))
    printf 'skip  %s  %s\n' "$where" "$cmd"
    continue
  fi
  printf 'run   %s  %s\n' "$where" "$cmd"
  c0=$SECONDS
  rc=0
  (cd "$work" && timeout "$timeout_s" bash -o pipefail -c "$cmd") >"$work/.log" 2>&1 || rc=$?
  if ((rc != 0)); then
    echo "---- output of the failing command ----" >&2
    tail -n 40 "$work/.log" >&2
    echo "readme-commands: FAILED (exit $rc) at $where: $cmd" >&2
    exit 1
  fi
  ran=$((ran + 1))
  printf '      ok in %d s\n' "$((SECONDS - c0))"
done
echo "readme-commands: $ran commands ran, $skipped skipped, all passed in $((SECONDS - t0)) s"
