#!/usr/bin/env bash
# Convergence study of the ring test (docs/validation.md): N = 10k, 30k, 100k particles at two mean
# neighbour numbers, from tau = 0.018 to 0.09. Writes runs/convergence/table.md.
# Usage: bench/convergence.sh [N ...]   (default: 10000 30000 100000)
set -euo pipefail
cd "$(dirname "$0")/.."
exe=build/release/sphdisk
out=runs/convergence
mkdir -p "$out"
sizes=("${@:-10000 30000 100000}")
[ $# -gt 0 ] || sizes=(10000 30000 100000)
for n in "${sizes[@]}"; do
  for nb in 60 120; do
    dir=$out/N${n}_nb${nb}
    start=$(date +%s.%N)
    $exe run configs/ring.toml -q --overwrite -o "$dir" --set problem.particles=$n --set sph.neighbours=$nb \
      --set 'output.tau=[0.036, 0.09]' > /dev/null
    end=$(date +%s.%N)
    awk -v a="$start" -v b="$end" 'BEGIN { print b - a }' > "$dir/wall_seconds.txt"
    $exe analyze "$dir/snapshot_002.hdf5" --json "$dir/analysis.json" > "$dir/analysis.txt"
    echo "done N=$n nb=$nb in $(cat "$dir/wall_seconds.txt") s"
  done
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
rows = ["| N | neighbours (start) | binned Sigma L1 (annulus mass) | binned particle Sigma L1 (SPH) | Sigma scatter (rms) | v_r L1 (drift) | v_r L1 (particles) | steps | wall time [s] |",
        "|---|---|---|---|---|---|---|---|---|"]
for d in sorted(out.glob("N*_nb*"), key=lambda p: (int(p.name.split("_")[0][1:]), p.name)):
    a = json.loads((d / "analysis.json").read_text())
    n, nb = d.name.split("_")
    steps = sum(1 for _ in open(d / "diagnostics.csv")) - 2
    wall = float((d / "wall_seconds.txt").read_text())
    rows.append(f"| {n[1:]} | {nb[2:]} | {a['mass_sigma_l1']:.4f} | {a['sigma_l1']:.4f} | {a['sigma_scatter']:.3f} | "
                f"{a['vr_drift_l1']:.3f} | {a['vr_l1']:.3f} | {steps} | {wall:.0f} |")
(out / "table.md").write_text("\n".join(rows) + "\n")
print("\n".join(rows))
PY
