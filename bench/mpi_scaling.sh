#!/usr/bin/env bash
# Strong scaling over MPI ranks (P98 Figs. 9 and 10): ring runs of a fixed number of steps on
# 1..R ranks x T threads for several particle numbers; time per step, speedup, efficiency,
# communication share and load imbalance per run from each rank's phase timers (ranks.json).
# Writes runs/bench/mpi_scaling_SMOOTHING.csv and .png. Run on an otherwise idle machine; ranks beyond the
# core count are oversubscribed and measure nothing about scaling.
# Usage: bench/mpi_scaling.sh [--ranks "1 2"] [--threads 1] [--steps 40] [--smoothing adaptive]
#                             [--repeats 1] [N ...]   (default N: 10000 100000 500000)
# --repeats K runs every rank count K times, interleaved (1, 2, 1, 2, ...: a VM's slow spells then
# hit all rank counts alike); the CSV gives the median time per step and the range of efficiencies.
set -euo pipefail
cd "$(dirname "$0")/.."
ranks="1 2" threads=1 steps=40 smoothing=adaptive repeats=1
while [ $# -gt 0 ]; do
  case $1 in
    --ranks) ranks=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    --smoothing) smoothing=$2; shift 2 ;;
    --repeats) repeats=$2; shift 2 ;;
    *) break ;;
  esac
done
sizes=("$@")
[ $# -gt 0 ] || sizes=(10000 100000 500000)
out=runs/bench/mpi_scaling
mkdir -p "$out"
rm -rf "$out"/N*_t${threads}_${smoothing}_k*  # earlier repeats of this set-up
for n in "${sizes[@]}"; do
  for k in $(seq 1 "$repeats"); do for r in $ranks; do
    dir=$out/N${n}_r${r}_t${threads}_${smoothing}_k$k
    # OpenMPI binds each of up to 2 ranks to one core by default: a rank's threads would share it.
    bind=(); [ "$threads" -gt 1 ] && bind=(--bind-to none)
    mpirun -np "$r" "${bind[@]}" --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS="$threads" \
      build/release/sphdisk run configs/ring.toml -q --overwrite -o "$dir" --set problem.particles="$n" \
      --set "sph.smoothing=\"$smoothing\"" --set run.max_steps="$steps" --set checkpoint.every_seconds=0 \
      --set 'output.tau=[0.126]' --set 'integrator.scheme="leapfrog"' --set 'sph.pair_lists="stored"' > /dev/null
    echo "done N=$n ranks=$r threads=$threads repeat=$k"
  done; done
done
/usr/bin/python3 - "$out" "$threads" "$smoothing" <<'PY'
import csv, json, pathlib, statistics, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
out, threads, smoothing = pathlib.Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
runs = []
for d in sorted(out.glob(f"N*_r*_t{threads}_{smoothing}_k*")):
    n = int(d.name.split("_")[0][1:]); r = int(d.name.split("_")[1][1:]); k = int(d.name.split("_k")[-1])
    diag = list(csv.DictReader(open(d / "diagnostics.csv")))
    steps = int(diag[-1]["step"]) - int(diag[0]["step"])
    loop = float(diag[-1]["wall_time"]) - float(diag[0]["wall_time"])  # the steps only (not the start)
    ranks = json.loads((d / "ranks.json").read_text())
    total = [sum(v for k, v in x["timers"].items() if k not in ("io",)) for x in ranks]
    comm = [x["timers"].get("communication", 0.0) for x in ranks]
    work = [t - c for t, c in zip(total, comm)]
    runs.append(dict(particles=n, ranks=r, repeat=k, threads=threads, smoothing=smoothing, steps=steps,
                     seconds_per_step=loop / steps, updates_per_second=n * steps / loop,
                     communication_share=sum(comm) / sum(total),
                     imbalance=max(work) / (sum(work) / len(work)),
                     ghosts_per_rank=sum(x["ghosts"] for x in ranks) / len(ranks),
                     peak_rss_mb_max=max(x["peak_rss_bytes"] for x in ranks) / 2**20))
# Efficiency of each repeat against the one-rank run of the same repeat; medians over repeats.
for x in runs:
    base = next(b for b in runs if b["particles"] == x["particles"] and b["ranks"] == 1 and b["repeat"] == x["repeat"])
    x["efficiency"] = base["seconds_per_step"] / x["seconds_per_step"] / x["ranks"]
rows = []
for n, r in sorted({(x["particles"], x["ranks"]) for x in runs}):
    group = [x for x in runs if x["particles"] == n and x["ranks"] == r]
    row = {k: statistics.median(x[k] for x in group) if isinstance(group[0][k], float) else group[0][k]
           for k in group[0] if k != "repeat"}
    row["repeats"] = len(group)
    row["efficiency_min"] = min(x["efficiency"] for x in group)
    row["efficiency_max"] = max(x["efficiency"] for x in group)
    rows.append(row)
for row in rows:
    base = next(x for x in rows if x["particles"] == row["particles"] and x["ranks"] == 1)
    row["speedup"] = base["seconds_per_step"] / row["seconds_per_step"]
keys = ["particles", "ranks", "threads", "smoothing", "steps", "repeats", "seconds_per_step", "updates_per_second",
        "speedup", "efficiency", "efficiency_min", "efficiency_max", "communication_share", "imbalance",
        "ghosts_per_rank", "peak_rss_mb_max"]
path = out.parent / f"mpi_scaling_{smoothing}.csv"
with open(path, "w", newline="") as f:
    w = csv.DictWriter(f, keys); w.writeheader()
    for row in sorted(rows, key=lambda x: (x["particles"], x["ranks"])):
        w.writerow({k: (f"{row[k]:.4g}" if isinstance(row[k], float) else row[k]) for k in keys})
print(open(path).read())
fig, ax = plt.subplots(1, 2, figsize=(10, 4))
for n in sorted({x["particles"] for x in rows}):
    rs = sorted((x for x in rows if x["particles"] == n), key=lambda x: x["ranks"])
    ax[0].plot([x["ranks"] for x in rs], [x["efficiency"] for x in rs], "o-", label=f"N = {n}")
    ax[1].plot([x["ranks"] for x in rs], [100 * x["communication_share"] for x in rs], "o-", label=f"N = {n}")
ax[0].set(xlabel="MPI ranks", ylabel="parallel efficiency", ylim=(0, 1.1), title="strong scaling (P98 Fig. 9)")
ax[1].set(xlabel="MPI ranks", ylabel="communication + waiting [% of step]", title="communication (P98 Fig. 10)")
for a in ax: a.legend(); a.grid(alpha=0.3)
fig.tight_layout(); fig.savefig(out.parent / f"mpi_scaling_{smoothing}.png", dpi=120)
PY
