#!/usr/bin/env bash
# Convergence study of the ring test (docs/validation.md): N = 10k, 30k, 100k particles at two mean
# neighbour numbers, from tau = 0.018 to 0.09. Writes runs/convergence/table.md.
# Usage: bench/convergence.sh [--plain] [--neighbours "60 120"] [N ...]   (default N: 10000 30000 100000)
#   --plain: the paper's uncorrected velocity gradient (sph.gradient_correction = false)
set -euo pipefail
cd "$(dirname "$0")/.."
exe=build/release/sphdisk
out=runs/convergence
mkdir -p "$out"
variant="" correction=true neighbours="60 120"
while [ $# -gt 0 ]; do
  case $1 in
    --plain) variant=_plain correction=false; shift ;;
    --neighbours) neighbours=$2; shift 2 ;;
    *) break ;;
  esac
done
sizes=("$@")
[ $# -gt 0 ] || sizes=(10000 30000 100000)
for n in "${sizes[@]}"; do
  for nb in $neighbours; do
    dir=$out/N${n}_nb${nb}${variant}
    start=$(date +%s.%N)
    $exe run configs/ring.toml -q --overwrite -o "$dir" --set problem.particles=$n --set sph.neighbours=$nb \
      --set sph.gradient_correction=$correction --set 'output.tau=[0.036, 0.09]' > /dev/null
    end=$(date +%s.%N)
    awk -v a="$start" -v b="$end" 'BEGIN { print b - a }' > "$dir/wall_seconds.txt"
    $exe analyze "$dir/snapshot_002.hdf5" --json "$dir/analysis.json" > "$dir/analysis.txt"
    echo "done N=$n nb=$nb in $(cat "$dir/wall_seconds.txt") s"
  done
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
rows = ["| N | neighbours (start) | gradient | binned Sigma L1 (annulus mass) | binned particle Sigma L1 (SPH) | Sigma scatter (rms) | v_r L1 (drift) | v_r L1 (particles) | steps | wall time [s] |",
        "|---|---|---|---|---|---|---|---|---|---|"]
for d in sorted(out.glob("N*_nb*"), key=lambda p: (int(p.name.split("_")[0][1:]), p.name)):
    a = json.loads((d / "analysis.json").read_text())
    n, nb = d.name.split("_")[:2]
    gradient = "eq. 8 (plain)" if d.name.endswith("_plain") else "corrected"
    steps = sum(1 for _ in open(d / "diagnostics.csv")) - 2
    wall = float((d / "wall_seconds.txt").read_text())
    rows.append(f"| {n[1:]} | {nb[2:]} | {gradient} | {a['mass_sigma_l1']:.4f} | {a['sigma_l1']:.4f} | {a['sigma_scatter']:.3f} | "
                f"{a['vr_drift_l1']:.3f} | {a['vr_l1']:.3f} | {steps} | {wall:.0f} |")
(out / "table.md").write_text("\n".join(rows) + "\n")
print("\n".join(rows))
PY
