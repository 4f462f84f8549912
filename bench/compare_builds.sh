#!/usr/bin/env bash
# An earlier commit against the working tree's release build, on the same ring run, interleaved
# (earlier, current, earlier, current, ...) so that drifts of the machine's speed hit both alike.
# The earlier commit is built in a git worktree under ${TMPDIR:-/tmp}/sphdisk-builds/ (kept for
# later comparisons; outside the tree, so no tool mistakes it for project sources).
# Prints one line per run (build, user CPU seconds, wall seconds) and per round whether the two
# runs' diagnostics (every column but the wall time) are equal.
# Usage: [PARTICLES=100000] [STEPS=20] [THREADS=1] [ROUNDS=4] bench/compare_builds.sh COMMIT [KEY=VALUE ...]
#   KEY=VALUE: configuration overrides for both runs (--set), e.g. sph.smoothing=constant
set -euo pipefail
cd "$(dirname "$0")/.."
ref=$(git rev-parse --short "$1")
n=${PARTICLES:-100000} steps=${STEPS:-20} threads=${THREADS:-1} rounds=${ROUNDS:-4}
shift
sets=()
for kv in "$@"; do sets+=(--set "$kv"); done
base=${TMPDIR:-/tmp}/sphdisk-builds/$ref
if [ ! -x "$base/build/sphdisk" ]; then
  [ -d "$base" ] || git worktree add --detach "$base" "$ref" > /dev/null
  cmake --preset release -S "$base" -B "$base/build" > /dev/null
  cmake --build "$base/build" -j2 --target sphdisk > /dev/null
fi
out=runs/compare_builds
mkdir -p "$out"
physics() { cut -d, -f1-11 "$1/diagnostics.csv"; }
for round in $(seq "$rounds"); do
  for build in "$ref" current; do
    exe=build/release/sphdisk
    [ "$build" = current ] || exe=$base/build/sphdisk
    dir=$out/$build
    rm -rf "$dir"
    times=$(/usr/bin/time -f "%U %e" "$exe" run configs/ring.toml -o "$dir" --set problem.particles="$n" \
      --set run.max_steps="$steps" -t "$threads" ${sets[@]+"${sets[@]}"} -q 2>&1 > /dev/null | tail -1)
    echo "$build $times"
  done
  if cmp -s <(physics "$out/$ref") <(physics "$out/current"); then echo "round $round: same diagnostics"
  else echo "round $round: diagnostics differ"; fi
done
