#!/usr/bin/env bash
# Variants of the ring run side by side: the same start run for a number of steps with every
# combination of the settings named, interleaved (all combinations, then again, ROUNDS times) so
# that drifts of the machine's speed hit every variant alike; one CSV row per run with the wall
# time, evaluations, list builds, particle updates, peak memory per particle and phase times
# (bench/run_summary.py).
# Usage: [PARTICLES=100000] [STEPS=40] [THREADS=2] [ROUNDS=2] bench/ring_variants.sh NAME KEY=V1,V2,... ...
#   A value may carry more settings after '+', e.g. integrator.scheme=leapfrog,block+run.max_steps=3
#   (a block step is a whole cycle). String values are written without TOML quotes.
# Writes runs/NAME/N<N>/summary.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
exe=build/release/sphdisk
name=$1
shift
n=${PARTICLES:-100000} steps=${STEPS:-40} threads=${THREADS:-2} rounds=${ROUNDS:-2}
out=runs/$name/N$n
mkdir -p "$out"
summary=$out/summary.csv
keys=()
for axis in "$@"; do keys+=("${axis%%=*}"); done
[ -f "$summary" ] || bench/run_summary.py --header "${keys[@]}" particles threads > "$summary"
# One line per combination: the values (for the CSV, tab-separated), then the --set arguments.
combinations=$(/usr/bin/python3 - "$@" <<'PY'
import itertools, re, sys
axes = [(a.split("=", 1)[0], a.split("=", 1)[1].split(",")) for a in sys.argv[1:]]
def toml(v):
    return v if re.fullmatch(r"[-+0-9.eE]+|true|false", v) else f'"{v}"'
for combo in itertools.product(*[[(k, v) for v in values] for k, values in axes]):
    sets = []
    for k, v in combo:
        value, *extra = v.split("+")
        sets += [f"{k}={toml(value)}"] + extra
    print("\t".join(v.split("+")[0] for _, v in combo) + "\t|\t" + "\t".join(sets))
PY
)
for round in $(seq "$rounds"); do
  while IFS= read -r line; do
    IFS=$'\t' read -ra values <<< "${line%%$'\t'|*}"
    IFS=$'\t' read -ra sets <<< "${line#*|$'\t'}"
    args=()
    for s in "${sets[@]}"; do args+=(--set "$s"); done
    dir=$out/$(IFS=-; echo "${values[*]}")
    start=$(date +%s.%N)
    $exe run configs/ring.toml -q --overwrite -o "$dir" -t "$threads" --set problem.particles=$n \
      --set run.max_steps=$steps --set checkpoint.every_seconds=0 "${args[@]}" > /dev/null
    end=$(date +%s.%N)
    bench/run_summary.py "$dir" "$start" "$end" "${values[@]}" "$n" "$threads" >> "$summary"
    tail -1 "$summary"
  done <<< "$combinations"
done
