#!/usr/bin/env bash
# Work and traffic counters of short ring runs on many ranks, for bench/scaling_model.py: per rank
# and run, owned particles, ghosts, pair interactions, h solves and the bytes, messages and
# reductions each rank sent, over the steps alone (ranks.json's "steps"). Counters do not depend on
# the machine's speed, so ranks may be oversubscribed far beyond the cores.
# Usage: bench/scaling_counters.sh OUT.csv [--ranks "1 2 4 8 16 32 64"] [--steps 2] [N ...]
set -euo pipefail
cd "$(dirname "$0")/.."
out=$1; shift
ranks="1 2 4 8 16 32 64" steps=2
while [ $# -gt 0 ]; do
  case $1 in
    --ranks) ranks=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    *) break ;;
  esac
done
sizes=("$@")
[ $# -gt 0 ] || sizes=(100000 500000 2000000)
keep=runs/scale/counters
mkdir -p "$keep"
for n in "${sizes[@]}"; do for r in $ranks; do
  dir=runs/scale/run_N${n}_P${r}
  start=$(date +%s)
  mpirun -np "$r" --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 -x OMPI_MCA_mpi_yield_when_idle=1 \
    build/release/sphdisk run configs/ring.toml -q --overwrite -o "$dir" --set problem.particles="$n" \
    --set run.max_steps="$steps" --set checkpoint.every_seconds=0 --set 'output.tau=[0.126]' \
    --set 'integrator.scheme="leapfrog"' --set 'sph.pair_lists="stored"' > /dev/null
  cp "$dir/ranks.json" "$keep/ranks_N${n}_P${r}.json"
  cp "$dir/diagnostics.csv" "$keep/diagnostics_N${n}_P${r}.csv"
  rm -rf "$dir"
  echo "N=$n ranks=$r: $(( $(date +%s) - start )) s"
done; done
/usr/bin/python3 - "$keep" "$out" <<'PY'
import csv, json, pathlib, sys
keep, out = pathlib.Path(sys.argv[1]), sys.argv[2]
kinds = ("migration", "halo_build", "halo_refresh", "reductions")
fields = ("exchanges", "messages", "bytes", "reductions", "reduction_bytes")
rows = []
for f in sorted(keep.glob("ranks_N*_P*.json")):
    n, p = (int(x[1:]) for x in f.stem.split("_")[1:])
    for x in json.loads(f.read_text()):
        s = x["steps"]
        row = dict(particles=n, ranks=p, rank=x["rank"], owned=x["particles"], ghosts=x["ghosts"],
                   count_imbalance=x["count_imbalance"], steps=s["steps"], rate_evaluations=s["rate_evaluations"],
                   particle_updates=s["particle_updates"], pair_interactions=s["pair_interactions"],
                   h_solves=s["smoothing_length_solves"], h_sums=s["smoothing_length_sums"])
        for k in kinds:
            for q in fields:
                row[f"{k}_{q}"] = s["traffic"][k][q]
        rows.append(row)
with open(out, "w", newline="") as fh:
    w = csv.DictWriter(fh, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
print(f"{len(rows)} rows -> {out}")
PY
