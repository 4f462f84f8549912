#!/usr/bin/env bash
# A short fuzz run for CI, as deterministic as the targets allow: builds the libFuzzer
# targets with clang, replays every input that once crashed a parser (tests/fuzz_regressions/), then
# mutates the seed corpora for a fixed number of runs from a fixed seed. Any crash, sanitizer report,
# leak of a non-UserError exception or multi-line error message fails the test; the crashing input
# is kept under build/fuzz/artifacts/ to be added to tests/fuzz_regressions/.
# Deterministic: a fixed seed alone is not enough. With address randomisation the first executions
# of the same inputs already cover different edges, and libFuzzer re-reads its corpus directory
# every second (-reload), so two runs with the same sources can take different mutation paths and
# find different crashers. With `setarch -R` and -reload=0, and the targets run from a temporary
# directory with relative paths and a fixed environment (fuzz() below), the configuration run ends
# with the same coverage, features and corpus in every run and in checkouts at different paths. The
# snapshot run reads each input in a forked child (io/hdf5_util.cpp), whose fate under memory
# limits can depend on the machine's state, so its coverage may differ slightly between runs
# (docs/reliability.md, "Fuzzing"). Where the system refuses to turn randomisation off (some
# container seccomp profiles), the run goes on without it and says so.
#   usage: short_fuzz_run.sh SOURCE_DIR [CONFIG_RUNS] [SNAPSHOT_RUNS]
set -euo pipefail
src=$(cd "$1" && pwd)
config_runs=${2:-20000}
snapshot_runs=${3:-300}
build="$src/build/fuzz"

if ! command -v clang++ > /dev/null; then
  echo "short_fuzz_run: clang++ not found; run scripts/install-deps.sh" >&2
  exit 1
fi
cmake -S "$src/fuzz" -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang > /dev/null
cmake --build "$build" -j2 > /dev/null

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$build/artifacts" "$work/artifacts" "$work/regressions"
cp "$build/fuzz_config" "$build/fuzz_snapshot" "$work/"
cp "$src"/tests/fuzz_regressions/* "$work/regressions/"
cp -r "$src/fuzz/corpus/config" "$src/fuzz/corpus/snapshot" "$work/"
norandom=()
if setarch "$(uname -m)" -R true 2> /dev/null; then
  norandom=(setarch "$(uname -m)" -R)
else
  echo "short_fuzz_run: note: address randomisation cannot be turned off here; the mutation path may differ between runs"
fi
# Runs a target from $work with relative paths and a fixed, minimal environment, so that neither the
# checkout's location nor the caller's variables shift the stack (without randomisation, the
# strings of the command line and environment set where it starts). The snapshot reader forks a
# child per read (io/hdf5_util.hpp); a child that runs out of memory on a corrupt size is refused by
# design, so ASan may return null instead of aborting.
fuzz() {
  local target=$1 log=$2
  shift 2
  (cd "$work" && env -i PATH=/usr/bin:/bin ASAN_OPTIONS=allocator_may_return_null=1:detect_leaks=0 \
    ${norandom[@]+"${norandom[@]}"} "./fuzz_$target" -seed=1 -reload=0 -rss_limit_mb=4096 -malloc_limit_mb=4096 \
    -artifact_prefix=artifacts/ -print_final_stats=1 "$@") > "$log" 2>&1 && return 0
  tail -40 "$log"
  cp "$work"/artifacts/* "$build/artifacts/" 2> /dev/null || true
  echo "short_fuzz_run: fuzz_$target failed; its input is under $build/artifacts/" >&2
  exit 1
}

echo "== replaying crashers found earlier"
for target in config:toml snapshot:hdf5; do
  inputs=()
  for f in "$work"/regressions/*."${target#*:}"; do inputs+=("regressions/${f##*/}"); done  # relative to $work
  fuzz "${target%%:*}" "$work/replay.log" "${inputs[@]}"
  echo "fuzz_${target%%:*}: $(grep -c '^Executed' "$work/replay.log") regression inputs pass"
done

report() {  # name, log: runs and executions per second from libFuzzer's final stats
  local runs secs
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$2")
  secs=$(sed -n 's/^Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$2")
  echo "$1: $runs inputs in ${secs}s ($(sed -n 's/^stat::average_exec_per_sec: *//p' "$2") exec/s); at the end$(sed -n 's/^#[0-9]*[[:space:]]*DONE *\(cov: [0-9]* ft: [0-9]* corp: [^ ]*\).*/ \1/p' "$2")"
}

echo "== mutating the configuration corpus ($config_runs runs)"
fuzz config "$work/config.log" -runs="$config_runs" -max_len=4096 config
report fuzz_config "$work/config.log"

echo "== mutating the snapshot/checkpoint corpus ($snapshot_runs runs)"
fuzz snapshot "$work/snapshot.log" -runs="$snapshot_runs" snapshot
report fuzz_snapshot "$work/snapshot.log"
