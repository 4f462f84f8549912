#!/usr/bin/env bash
# The Sedov-Taylor blast wave (configs/sedov.toml, problem.type = "sedov"): a 3D run of 32^3
# particles to t = 0.05 compared by `sphdisk analyze` with the similarity solution (the particles'
# density, velocity and pressure L1, the densest shell's radius against the shock's, the energy
# budget) and drawn by `sphdisk report`, a 2D (cylindrical) one, and the same bits with 1 and 3 threads (and on 3 MPI ranks where
# MPIEXEC is given). The limits hold the measured values with a margin (docs/validation.md, "The
# Sedov-Taylor blast wave"); without the artificial viscosity the 3D run fails four of them.
# Usage: sedov_blast.sh SPHDISK [MPIEXEC]
set -uo pipefail
sphdisk=$1
mpiexec=${2:-}
config="$(dirname "$0")/../../configs/sedov.toml"
. "$(dirname "$0")/../lib/checks.sh"  # $work, ok, bad, finish

# check_blast JSON LABEL RHO_L1 VR_L1 P_L1 PEAK_LO PEAK_DENSITY: the analysis against the limits.
check_blast() {
  /usr/bin/python3 - "$@" <<'PY'
import json, sys
path, label, rho_l1, vr_l1, p_l1, peak_lo, peak_density = sys.argv[1], sys.argv[2], *map(float, sys.argv[3:])
a = json.load(open(path))
checks = [
    ("density L1 %.4f <= %g" % (a["rho_l1"], rho_l1), a["rho_l1"] <= rho_l1),
    ("radial velocity L1 %.4f <= %g" % (a["vr_l1"], vr_l1), a["vr_l1"] <= vr_l1),
    ("pressure L1 %.4f <= %g" % (a["p_l1"], p_l1), a["p_l1"] <= p_l1),
    ("densest shell at %.3f of the shock radius, within [%g, 1.02]" % (a["peak_radius"] / a["shock_radius"], peak_lo),
     peak_lo <= a["peak_radius"] / a["shock_radius"] <= 1.02),
    ("densest shell's density %.3f >= %g (strong-shock jump 4)" % (a["peak_density"], peak_density), a["peak_density"] >= peak_density),
    ("energy budget %.2e within 3e-3" % (a["total_energy"] / a["initial_energy"] - 1), abs(a["total_energy"] / a["initial_energy"] - 1) <= 3e-3),
]
failed = 0
for text, good in checks:
    print(("ok   " if good else "FAIL ") + label + ": " + text)
    failed += not good
sys.exit(1 if failed else 0)
PY
}
count_checks() {  # check_blast's lines into the tallies (fed by process substitution, not a pipe's subshell)
  while IFS= read -r line; do
    case $line in ok*) ok "${line#ok   }" ;; FAIL*) bad "${line#FAIL }" ;; esac
  done
}

OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q --set problem.particles=32768 --set 'output.times=[0.05]' -o "$work/3d" > "$work/3d.out" 2>&1 \
  || bad "3D blast wave run"
"$sphdisk" analyze "$work/3d/snapshot_001.hdf5" --json "$work/3d.json" > /dev/null || bad "analyze of the 3D blast wave"
grep -q "^Sedov-Taylor blast wave, 3D" "$work/3d.out" && ok "the run ends with the comparison" || bad "the run's closing table is not the blast wave's"
count_checks < <(check_blast "$work/3d.json" "3D, 32^3" 0.26 0.60 0.70 0.85 1.8)
# The report: the profiles against the solution, and the same L1 as analyze's in its table.
"$sphdisk" report "$work/3d" > /dev/null 2>&1 || bad "report of the blast wave"
rho_l1=$(/usr/bin/python3 -c "import json, sys; print('%.4f' % json.load(open(sys.argv[1]))['rho_l1'])" "$work/3d.json")
if [ -s "$work/3d/report/sedov_001.png" ] && grep -q "| snapshot_001.hdf5 | 0.05 | .* | $rho_l1 |" "$work/3d/report/report.md"; then
  ok "the report draws the profiles and tabulates analyze's density L1 ($rho_l1)"
else bad "the blast wave's report lacks its figure or analyze's density L1 ($rho_l1)"; fi

OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q --set problem.particles=4096 --set sph.dimension=2 --set sph.neighbours=30 \
  --set 'output.times=[0.05]' -o "$work/2d" > /dev/null 2>&1 || bad "2D blast wave run"
"$sphdisk" analyze "$work/2d/snapshot_001.hdf5" --json "$work/2d.json" > /dev/null || bad "analyze of the 2D blast wave"
count_checks < <(check_blast "$work/2d.json" "2D, 64^2" 0.19 0.40 0.43 0.88 2.2)

# Same bits for any thread (and rank) count, with the leapfrog and respa.
small=(-q --set problem.particles=4096 --set 'output.times=[0.005, 0.01]')
for scheme in leapfrog respa; do
  for t in 1 3; do
    OMP_NUM_THREADS=$t "$sphdisk" run "$config" "${small[@]}" --set "integrator.scheme=\"$scheme\"" -o "$work/$scheme$t" > /dev/null 2>&1 \
      || bad "blast wave with $scheme on $t threads"
  done
  if cmp -s "$work/${scheme}1/snapshot_002.hdf5" "$work/${scheme}3/snapshot_002.hdf5"; then
    ok "blast wave, $scheme: same snapshots with 1 and 3 threads"
  else bad "blast wave, $scheme: snapshots differ between 1 and 3 threads"; fi
done
if [ -n "$mpiexec" ]; then
  OMP_NUM_THREADS=1 "$mpiexec" --oversubscribe --allow-run-as-root -n 3 "$sphdisk" run "$config" "${small[@]}" -o "$work/ranks3" > /dev/null 2>&1 \
    || bad "blast wave on 3 ranks"
  if cmp -s "$work/leapfrog1/snapshot_002.hdf5" "$work/ranks3/snapshot_002.hdf5"; then ok "blast wave: same snapshot on 3 ranks as on 1"
  else bad "blast wave: the snapshot on 3 ranks differs from 1 rank's"; fi
fi

finish "sedov_blast: "
