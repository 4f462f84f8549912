#!/usr/bin/env bash
# Convergence study of the ring test (docs/validation.md): N = 10k, 30k, 100k particles at two mean
# neighbour numbers, from tau = 0.018 to 0.09. Writes runs/convergence/table.md.
# Usage: bench/convergence.sh [--plain] [--kernel NAME] [--neighbours "60 120"] [N ...]
#   (default N: 10000 30000 100000)
#   --plain: the paper's uncorrected velocity gradient (sph.gradient_correction = "none")
#   --kernel: cubic (default), wendland_c2 or wendland_c4; the run directory gets the suffix _wc2/_wc4
#   --constant: one global h (P98 sec. 5.3) instead of adaptive smoothing lengths; suffix _const
set -euo pipefail
cd "$(dirname "$0")/.."
exe=build/release/sphdisk
out=runs/convergence
mkdir -p "$out"
variant="" correction='"mixed"' neighbours="60 120" kernel=cubic smoothing=adaptive
while [ $# -gt 0 ]; do
  case $1 in
    --plain) variant=_plain correction='"none"'; shift ;;
    --constant) variant="${variant}_const" smoothing=constant; shift ;;
    --neighbours) neighbours=$2; shift 2 ;;
    --kernel) kernel=$2; variant="${variant}_wc${2#wendland_c}"; shift 2 ;;
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
      --set sph.gradient_correction=$correction --set "sph.kernel=\"$kernel\"" --set "sph.smoothing=\"$smoothing\"" --set 'output.tau=[0.036, 0.09]' > /dev/null
    end=$(date +%s.%N)
    awk -v a="$start" -v b="$end" 'BEGIN { print b - a }' > "$dir/wall_seconds.txt"
    $exe analyze "$dir/snapshot_002.hdf5" --json "$dir/analysis.json" > "$dir/analysis.txt"
    echo "done N=$n nb=$nb in $(cat "$dir/wall_seconds.txt") s"
  done
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys, pathlib, warnings
sys.path.insert(0, "bench")
from fit_viscous_time import fit
out = pathlib.Path(sys.argv[1])
import tomllib
rows = ["| N | smoothing | kernel | neighbours | gradient | binned Sigma L1 (annulus mass) | tau*/tau (L1 there) | binned particle Sigma L1 (SPH) | Sigma scatter (rms) | v_r L1 (drift) | v_r L1 (particles) | steps | wall time [s] |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
for d in sorted((p for p in out.glob("N*_nb*") if (p / "analysis.json").exists()), key=lambda p: (int(p.name.split("_")[0][1:]), p.name)):
    a = json.loads((d / "analysis.json").read_text())
    cfg = tomllib.loads((d / "config.toml").read_text())
    n, nb, kernel = cfg["problem"]["particles"], cfg["sph"]["neighbours"], cfg["sph"]["kernel"]
    smoothing = cfg["sph"].get("smoothing", "constant")
    gradient = {True: "linear", False: "none"}.get(cfg["sph"].get("gradient_correction", "mixed"), cfg["sph"].get("gradient_correction", "mixed"))
    steps = sum(1 for _ in open(d / "diagnostics.csv")) - 2
    with warnings.catch_warnings():  # the analysis is of the last snapshot (tau = 0.09)
        warnings.simplefilter("ignore")
        tau, _, best, l1_best = fit(sorted(d.glob("snapshot_*.hdf5"))[-1])
    wall = float((d / "wall_seconds.txt").read_text())
    rows.append(f"| {n} | {smoothing} | {kernel} | {nb:g} | {gradient} | {a['mass_sigma_l1']:.4f} | {best / tau:.3f} ({l1_best:.4f}) | {a['sigma_l1']:.4f} | {a['sigma_scatter']:.3f} | "
                f"{a['vr_drift_l1']:.3f} | {a['vr_l1']:.3f} | {steps} | {wall:.0f} |")
(out / "table.md").write_text("\n".join(rows) + "\n")
print("\n".join(rows))
PY
