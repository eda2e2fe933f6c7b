#!/usr/bin/env bash
# Builds the libFuzzer targets with clang, optimised and with ASan+UBSan, and runs each in turn.
#
#   scripts/fuzz.sh [SECONDS]                   every target for SECONDS (default 15): CI's smoke run
#   scripts/fuzz.sh --minutes N [TARGET...]     long mode: N minutes per target (default: all), then
#                                               the figures go into fuzz/README.md and the minimised
#                                               corpus into fuzz/corpus/<target>/ (N = 0: only that)
#   --build DIR                                 use the fuzz targets of the configured build folder
#                                               DIR (scripts/test.sh's smoke: build-asan, -O0);
#                                               default: build-fuzz, CMakePresets.json "fuzz" (-O2)
#
# Where inputs live (see fuzz/README.md):
#   fuzz/seeds/<target>/    hand-written seeds, each one a case someone meant
#   fuzz/corpus/<target>/   the minimised corpus in the repository: what long runs found beyond the
#                           seeds, so a fresh clone starts deep
#   $CANFLEET_FUZZ_CACHE/<target>/   the growing corpus, kept across runs outside the clone as
#                           ccache keeps its cache; default ${XDG_CACHE_HOME:-$HOME/.cache}/canfleet-fuzz.
#   fuzz/README.md's table  the ledger: each long run adds its executions to its target's total
#                           there, so the total counts every long run committed, on any machine.
# Environment: FUZZ_JOBS (build jobs, default nproc).
set -euo pipefail
cd "$(dirname "$0")/.."
# CI builds a fresh clone in a new folder each time: relative paths let ccache hit across clones.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true

seconds=15
minutes=""
build=""
only=()
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes)
      minutes=${2:?--minutes needs a number}
      shift 2
      ;;
    --build)
      build=${2:?--build needs a build folder}
      shift 2
      ;;
    --help | -h)
      sed -n '2,20p' "$0"
      exit 0
      ;;
    [0-9]*)
      seconds=$1
      shift
      ;;
    *)
      only+=("$1")
      shift
      ;;
  esac
done
[ -n "$minutes" ] && seconds=$((minutes * 60))
[ "$minutes" = 0 ] && seconds=0 # only re-minimise (below); never run libFuzzer with 0 = no limit

cache=${CANFLEET_FUZZ_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/canfleet-fuzz}
mkdir -p "$cache"

# Every target registers itself in fuzz/targets/<name>.cmake.
names=()
for f in fuzz/targets/*.cmake; do
  names+=("$(basename "$f" .cmake)")
done
if [ ${#only[@]} -gt 0 ]; then
  for n in "${only[@]}"; do
    [ -f "fuzz/targets/$n.cmake" ] || {
      echo "fuzz: no target $n (fuzz/targets/$n.cmake)" >&2
      exit 2
    }
  done
  names=("${only[@]}")
fi

if [ -z "$build" ]; then
  # CMakePresets.json "fuzz": clang -O2 with ASan+UBSan (an -O0 build runs ten times fewer inputs).
  build=build-fuzz
  cmake --preset fuzz >/dev/null
fi
[ -f "$build/CMakeCache.txt" ] || {
  echo "fuzz: $build is not a configured build folder" >&2
  exit 2
}
grep -q '^CANFLEET_FUZZ:BOOL=ON' "$build/CMakeCache.txt" || {
  echo "fuzz: $build was configured without CANFLEET_FUZZ=ON (presets \"fuzz\" and \"asan\" have it)" >&2
  exit 2
}
cmake --build "$build" -j "${FUZZ_JOBS:-$(nproc)}" --target "${names[@]/#/fuzz_}"

# One figures file and one log per target per invocation: two long runs may run side by side (one
# per core), of different targets or of the same one (they share its cache corpus, as libFuzzer's
# own -jobs do); each minimises and adds its rows to fuzz/README.md under a lock at the end.
figures=$(mktemp "$build/figures.XXXXXX.tsv")
failed=()
for name in "${names[@]}"; do
  [ "$seconds" = 0 ] && break
  bin=$build/fuzz/fuzz_$name
  corpus=$cache/$name
  mkdir -p "$corpus"
  dirs=("$corpus")
  for d in "fuzz/corpus/$name" "fuzz/seeds/$name"; do
    [ -d "$d" ] && dirs+=("$d")
  done
  log=$(mktemp "$build/fuzz_$name.XXXXXX.log")
  echo "fuzz: $name for ${seconds}s (corpus $corpus)"
  # -timeout: an input that runs 25 s is a hang (the slowest seed takes well under a second).
  if ! "$bin" -max_total_time="$seconds" -timeout=25 -print_final_stats=1 "${dirs[@]}" 2>"$log"; then
    tail -60 "$log"
    echo "fuzz: $name FAILED; the input is in the file named above (artifact_prefix: the working folder)"
    failed+=("$name")
    [ -n "$minutes" ] && continue # the long mode still runs the other targets
    exit 1
  fi
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  # The last status line: "#123 DONE cov: 1234 ft: 5678 corp: 321/45Kb ...".
  status=$(grep -E '^#[0-9]+.*cov: ' "$log" | tail -1 || true)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$status")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$status")
  files=$(find "$corpus" -type f | wc -l)
  echo "fuzz: $name executions ${executions:-?}, coverage ${cov:-?} edges, ${ft:-?} features, corpus $files files"
  printf '%s\t%s\t%s\t%s\t%s\n' "$name" "${executions:-0}" "${cov:-0}" "${ft:-0}" "$files" >>"$figures"
done

[ -n "$minutes" ] || exit 0

# Long mode: the repository's minimised corpus, kept small: an edge cover. libFuzzer's merge runs
# the seeds first, then every other input from the smallest up, and its control file lists for each
# input the edges no earlier input reached ("COV i edge..."); the inputs beyond the seeds that reach
# one are kept. (-merge=1's own choice keeps every input with a new feature, i.e. hit-count bucket:
# ten times more files for the same edges.)
minimise() { # TARGET: rewrites fuzz/corpus/TARGET, prints the number of files kept
  # Under the lock below: a run of the same target beside this one minimises after or before it.
  local name=$1 bin=$build/fuzz/fuzz_$1 work=$build/merge/$1 ctl=$build/merge/$1.ctl
  local snapshot=$build/merge/$1.cache
  rm -rf "$work" "$ctl" "$snapshot"
  mkdir -p "$work" "$build/merge/$name.new"
  [ -d "fuzz/seeds/$name" ] && cp "fuzz/seeds/$name"/* "$work"/
  # A snapshot of the cache corpus (hard links): a run of the same target still fuzzing beside this
  # one replaces inputs it reduces, and the merge must not look for a file that has gone since.
  cp -al "$cache/$name" "$snapshot" 2>/dev/null || { rm -rf "$snapshot" && cp -a "$cache/$name" "$snapshot"; }
  local from=("$snapshot")
  [ -d "fuzz/corpus/$name" ] && from+=("fuzz/corpus/$name")
  "$bin" -merge=1 -timeout=25 -merge_control_file="$ctl" "$work" "${from[@]}" 2>"$build/merge_$name.log" || {
    tail -30 "$build/merge_$name.log" >&2
    return 1
  }
  rm -rf "$build/merge/$name.new"
  mkdir -p "$build/merge/$name.new"
  python3 - "$ctl" "$build/merge/$name.new" <<'PY'
import hashlib, shutil, sys
lines = open(sys.argv[1], errors="replace").read().splitlines()
count, first = int(lines[0]), int(lines[1])
paths = lines[2:2 + count]
for line in lines[2 + count:]:
    parts = line.split()
    if len(parts) > 2 and parts[0] == "COV" and int(parts[1]) >= first:
        data = open(paths[int(parts[1])], "rb").read()
        open(sys.argv[2] + "/" + hashlib.sha1(data).hexdigest(), "wb").write(data)
PY
  rm -rf "fuzz/corpus/$name" "$snapshot"
  mv "$build/merge/$name.new" "fuzz/corpus/$name"
  find "fuzz/corpus/$name" -type f | wc -l
}

# The minimised corpus and the table in fuzz/README.md, under a lock: a run beside this one (of
# another target or the same) does not minimise or write at the same time.
exec 9>"$build/readme.lock"
flock 9
if [ "$minutes" = 0 ]; then # --minutes 0: only re-minimise (after a change of the cover rule)
  for name in "${names[@]}"; do
    echo "fuzz: $name minimised corpus: $(minimise "$name") files in fuzz/corpus/$name"
  done
  exit 0
fi

for name in "${names[@]}"; do
  case " ${failed[*]} " in *" $name "*) continue ;; esac # a failed target's corpus waits for its fix
  kept=$(minimise "$name") || exit 1
  size=$(du -sk --apparent-size "fuzz/corpus/$name" | cut -f1)
  echo "fuzz: $name minimised corpus: $kept files, ${size} KiB in fuzz/corpus/$name"
  sed -i "s|^$name\t.*|&\t$kept|" "$figures"
done

# The table: a row per target, replaced for the targets of this run; the total is the one in the
# table now (read under the lock, so a run of the same target that ended meanwhile is counted) plus
# this run's executions.
python3 - "$figures" "$minutes" <<'EOF'
import datetime
import re
import sys

figures_path, minutes = sys.argv[1], sys.argv[2]
readme_path = "fuzz/README.md"
start, end = "<!-- fuzz-figures:start -->", "<!-- fuzz-figures:end -->"
text = open(readme_path).read()
head, rest = text.split(start, 1)
table, tail = rest.split(end, 1)
rows = {}
for line in table.splitlines():
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) == 9 and cells[0] not in ("target", "") and not set(cells[0]) <= set("-"):
        rows[cells[0]] = cells
today = datetime.date.today().isoformat()
for line in open(figures_path):
    name, runs, cov, ft, files, kept = line.rstrip("\n").split("\t")
    total = int(rows[name][2].replace(",", "")) if name in rows else 0
    total += int(runs)
    rows[name] = [name, f"{int(runs):,}", f"{total:,}", cov, ft, files, kept, f"{minutes} min", today]
    print(f"fuzz: {name} executions in total {total:,}")
header = ("| target | executions (this run) | executions (in total) | coverage (edges) | features"
          " | corpus (files) | fuzz/corpus (files) | run | date |\n|---|---:|---:|---:|---:|---:|---:|---|---|\n")
body = "".join("| " + " | ".join(rows[k]) + " |\n" for k in sorted(rows))
open(readme_path, "w").write(head + start + "\n" + header + body + end + tail)
EOF
echo "fuzz: figures written to fuzz/README.md"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]} (their figures and corpus are not written)"
  exit 1
fi
