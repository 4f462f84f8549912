#!/usr/bin/env bash
# Neighbour-list reuse on the ring (sph.list_skin): the same start run for a number of steps with
# each skin, integrator and smoothing named, interleaved so that drifts of the machine's speed hit
# every variant alike; wall time, list builds per evaluation and the phase times of each run.
# Usage: [PARTICLES=100000] [STEPS=40] [THREADS=2] [ROUNDS=2] bench/list_reuse.sh
# Writes runs/list_reuse/N<N>/summary.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
exe=build/release/sphdisk
n=${PARTICLES:-100000} steps=${STEPS:-40} threads=${THREADS:-2} rounds=${ROUNDS:-2}
out=runs/list_reuse/N$n
mkdir -p "$out"
summary=$out/summary.csv
[ -f "$summary" ] || echo "date,smoothing,scheme,skin,particles,threads,steps,wall_s,evaluations,list_builds,search_s,list_check_s,pair_loops_s" > "$summary"
for round in $(seq "$rounds"); do
  for smoothing in constant adaptive; do
    for scheme in leapfrog respa; do
      for skin in 0 0.1 0.2 0.3; do
        dir=$out/$smoothing-$scheme-$skin
        start=$(date +%s.%N)
        $exe run configs/ring.toml -q --overwrite -o "$dir" -t "$threads" --set problem.particles=$n \
          --set run.max_steps=$steps --set checkpoint.every_seconds=0 --set "sph.smoothing=\"$smoothing\"" \
          --set "integrator.scheme=\"$scheme\"" --set sph.list_skin=$skin > /dev/null
        end=$(date +%s.%N)
        /usr/bin/python3 - "$dir" "$smoothing" "$scheme" "$skin" "$n" "$threads" "$steps" "$start" "$end" >> "$summary" <<'PY'
import datetime, json, sys
d, smoothing, scheme, skin, n, threads, steps, start, end = sys.argv[1:]
r = json.load(open(f"{d}/ranks.json"))[0]
t = r["timers"]
print(f"{datetime.date.today()},{smoothing},{scheme},{skin},{n},{threads},{steps},{float(end) - float(start):.2f},"
      f"{r['rate_evaluations']},{r['list_builds']},{t.get('cell_build', 0) + t.get('neighbour_search', 0):.2f},"
      f"{t.get('list_check', 0):.2f},{t['density'] + t['velocity_gradient'] + t['forces']:.2f}")
PY
        tail -1 "$summary"
      done
    done
  done
done
