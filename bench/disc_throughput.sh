#!/usr/bin/env bash
# Throughput on Phantom's test disc (configs/disc_phantom_like.toml, one orbit): block steps and the
# leapfrog on 1 and 2 threads, for each sphdisk binary given, interleaved round by round so that
# drifts of the machine's speed hit every binary alike (docs/performance.md, "Three dimensions").
# Prints per run: round, scheme, threads, binary, wall s, user s, peak RSS KiB, particle updates,
# steps, rate evaluations, updates/s per core.
# Usage: [ROUNDS=2] bench/disc_throughput.sh SPHDISK [SPHDISK ...]
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${ROUNDS:-2}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for r in $(seq 1 "$rounds"); do
  for scheme in block leapfrog; do
    for threads in 1 2; do
      for bin in "$@"; do
        rm -rf "$out/run"
        /usr/bin/time -f "%e %U %M" -o "$out/time" "$bin" run configs/disc_phantom_like.toml -q -o "$out/run" -t "$threads" \
          --set "integrator.scheme=\"$scheme\"" > /dev/null
        read -r wall user rss < "$out/time"
        read -r updates steps evaluations < <(/usr/bin/python3 -c "import json, sys; d = json.load(open(sys.argv[1]))[0]; \
print(d['steps']['particle_updates'], d['steps']['steps'], d['rate_evaluations'])" "$out/run/ranks.json")
        per_core=$(/usr/bin/python3 -c "print(f'{$updates / $wall / $threads:.3g}')")
        echo "$r $scheme $threads $bin $wall $user $rss $updates $steps $evaluations $per_core"
      done
    done
  done
done
