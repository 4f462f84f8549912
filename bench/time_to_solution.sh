#!/usr/bin/env bash
# Time to solution of the ring: the same initial conditions run from tau =
# 0.018 to 0.09 with each integrator named, one after the other on the same machine, with the
# binned Sigma error at tau = 0.09 (annulus mass, docs/validation.md) and the work done.
# Usage: bench/time_to_solution.sh [--particles N] [--threads T] [--set KEY=VALUE ...] [LABEL=SETTINGS ...]
#   LABEL=SETTINGS: a name and the --set overrides of one variant, separated by spaces; default:
#     leapfrog='integrator.scheme="leapfrog"'  respa='integrator.scheme="respa"'
# Writes runs/time_to_solution/N<N>/<label>/ and runs/time_to_solution/N<N>/summary.csv.
# SPHDISK=path: another build's executable (e.g. an earlier commit's, bench/compare_builds.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
exe=${SPHDISK:-build/release/sphdisk}
n=100000 threads=2 common=()
while [ $# -gt 0 ]; do
  case $1 in
    --particles) n=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --set) common+=(--set "$2"); shift 2 ;;
    *) break ;;
  esac
done
variants=("$@")
[ $# -gt 0 ] || variants=('leapfrog=integrator.scheme="leapfrog"' 'respa=integrator.scheme="respa"')
out=runs/time_to_solution/N$n
mkdir -p "$out"
summary=$out/summary.csv
[ -f "$summary" ] || echo "date,label,settings,particles,threads,wall_s,steps,evaluations,particle_updates,pair_interactions,mass_sigma_l1,sigma_l1,vr_drift_l1" > "$summary"
for v in "${variants[@]}"; do
  label=${v%%=*} settings=${v#*=}
  sets=()
  for s in $settings; do sets+=(--set "$s"); done
  dir=$out/$label
  start=$(date +%s.%N)
  $exe run configs/ring.toml -q --overwrite -o "$dir" -t "$threads" --set problem.particles=$n \
    --set 'output.tau=[0.09]' "${common[@]}" "${sets[@]}" > /dev/null
  end=$(date +%s.%N)
  $exe analyze "$dir/snapshot_001.hdf5" --json "$dir/analysis.json" > "$dir/analysis.txt"
  /usr/bin/python3 - "$dir" "$label" "$settings" "$n" "$threads" "$start" "$end" >> "$summary" <<'PY'
import json, sys, csv
d, label, settings, n, threads, start, end = sys.argv[1:]
a = json.load(open(f"{d}/analysis.json"))
run = json.load(open(f"{d}/ranks.json"))
rows = list(csv.DictReader(open(f"{d}/diagnostics.csv")))
print(f"{__import__('datetime').date.today()},{label},\"{settings.replace(chr(34), chr(34) * 2)}\",{n},{threads},{float(end) - float(start):.1f},"
      f"{rows[-1]['step']},{run[0]['rate_evaluations']},{sum(r.get('particle_updates', 0) for r in run)},{sum(r['pair_interactions'] for r in run)},"
      f"{a['mass_sigma_l1']:.4f},{a['sigma_l1']:.4f},{a['vr_drift_l1']:.4f}")
PY
  tail -1 "$summary"
done
