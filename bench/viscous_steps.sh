#!/usr/bin/env bash
# Explicit viscous kicks against super-steps (integrator.viscous_update, integrate/super_steps.hpp)
# on the ring to tau = 0.09 with the default configuration (block steps, pairs searched anew): wall
# time, rate evaluations, particle updates per particle, spreading rate and annulus-mass L1 against
# its sampling floor, one CSV row per run. Run on an otherwise idle machine: OpenMP threads that
# share cores with other work make the wall times meaningless.
# Usage: [THREADS=2] [TAU=0.09] [CONFIG=configs/ring.toml] [EXE=build/release/sphdisk] [SETS="--set key=value ..."]
#        bench/viscous_steps.sh NAME "N1 N2 ..." "explicit super_steps"
# (CONFIG: the ring's configuration, P98's pressureless ring unless given; EXE: the sphdisk to time;
# SETS: further settings for every run of NAME)
# Writes runs/NAME/viscous_steps.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
exe=${EXE:-build/release/sphdisk} config=${CONFIG:-configs/ring.toml}
name=$1 sizes=$2 updates=${3:-"explicit super_steps"}
threads=${THREADS:-2} tau=${TAU:-0.09} sets=${SETS:-}
out=runs/$name
mkdir -p "$out"
csv=$out/viscous_steps.csv
[ -f "$csv" ] || echo "particles,viscous_update,threads,wall_s,evaluations,updates_per_particle,tau_fit_over_tau,annulus_l1,sampling_floor" > "$csv"
for n in $sizes; do
  for update in $updates; do
    dir=$out/N${n}_$update
    start=$(date +%s.%N)
    $exe run "$config" -q --overwrite -o "$dir" -t "$threads" --set problem.particles="$n" \
      --set "output.tau=[$tau]" --set "integrator.viscous_update=\"$update\"" --set checkpoint.every_seconds=0 $sets > /dev/null
    end=$(date +%s.%N)
    /usr/bin/python3 - "$dir" "$n" "$update" "$threads" "$start" "$end" "$exe" >> "$csv" <<'PY'
import json, re, subprocess, sys
d, n, update, threads, start, end, exe = sys.argv[1:8]
ranks = json.load(open(d + "/ranks.json"))
evaluations = ranks[0]["rate_evaluations"]
updates = sum(r["particle_updates"] for r in ranks)
text = subprocess.run([exe, "analyze", d + "/snapshot_001.hdf5"], capture_output=True, text=True, check=True).stdout
fit = re.search(r"tau\*/tau = ([0-9.]+)", text).group(1)
l1, floor = re.search(r"annulus-mass L1 ([0-9.]+) = [0-9.]+x the sampling floor ([0-9.]+)", text).groups()
print(f"{n},{update},{threads},{float(end) - float(start):.1f},{evaluations},{updates / int(n):.0f},{fit},{l1},{floor}")
PY
    tail -1 "$csv"
  done
done
