#!/usr/bin/env bash
# Stored neighbour lists against pairs searched anew by every pair loop (sph.pair_lists) on the
# ring: the same start run for a number of steps (leapfrog) or block cycles (block timesteps) with
# each storage, interleaved so that drifts of the machine's speed hit both alike; wall time, peak
# memory per particle and the phase times of each run.
# Usage: [PARTICLES=100000] [STEPS=40] [CYCLES=3] [THREADS=2] [ROUNDS=2] bench/pair_storage.sh
# Writes runs/pair_storage/N<N>/summary.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
exe=build/release/sphdisk
n=${PARTICLES:-100000} steps=${STEPS:-40} cycles=${CYCLES:-3} threads=${THREADS:-2} rounds=${ROUNDS:-2}
out=runs/pair_storage/N$n
mkdir -p "$out"
summary=$out/summary.csv
[ -f "$summary" ] || echo "date,smoothing,scheme,pair_lists,particles,threads,steps,wall_s,evaluations,particle_updates,peak_rss_bytes_per_particle,h_solve_and_search_s,density_s,velocity_gradient_s,forces_s" > "$summary"
for round in $(seq "$rounds"); do
  for smoothing in constant adaptive; do
    for scheme in leapfrog block; do
      n_steps=$steps
      [ $scheme = block ] && n_steps=$cycles
      for storage in stored rescan; do
        dir=$out/$smoothing-$scheme-$storage
        start=$(date +%s.%N)
        $exe run configs/ring.toml -q --overwrite -o "$dir" -t "$threads" --set problem.particles=$n \
          --set run.max_steps=$n_steps --set checkpoint.every_seconds=0 --set "sph.smoothing=\"$smoothing\"" \
          --set "integrator.scheme=\"$scheme\"" --set "sph.pair_lists=\"$storage\"" > /dev/null
        end=$(date +%s.%N)
        /usr/bin/python3 - "$dir" "$smoothing" "$scheme" "$storage" "$n" "$threads" "$n_steps" "$start" "$end" >> "$summary" <<'PY'
import datetime, json, sys
d, smoothing, scheme, storage, n, threads, steps, start, end = sys.argv[1:]
r = json.load(open(f"{d}/ranks.json"))[0]
t = r["timers"]
print(f"{datetime.date.today()},{smoothing},{scheme},{storage},{n},{threads},{steps},{float(end) - float(start):.2f},"
      f"{r['rate_evaluations']},{r['particle_updates']},{r['peak_rss_bytes'] / int(n):.0f},"
      f"{t.get('cell_build', 0) + t.get('neighbour_search', 0):.2f},{t['density']:.2f},{t['velocity_gradient']:.2f},{t['forces']:.2f}")
PY
        tail -1 "$summary"
      done
    done
  done
done
