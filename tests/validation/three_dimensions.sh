#!/usr/bin/env bash
# A 3D ring in vertical equilibrium (sph.dimension = 3, locally isothermal) and the power-law disc of
# configs/disc_phantom_like.toml end to end: the same bits
# with 1 and 3 threads (and on 3 MPI ranks where MPIEXEC is given), a run stopped inside a block
# cycle and resumed (on 2 ranks where MPIEXEC is given) ending with the uninterrupted run's
# snapshots, a snapshot that h5py and yt read as 3D, and `sphdisk analyze` comparing its vertically
# integrated Sigma with the analytic ring, and `sphdisk report` drawing it. A 3D checkpoint cannot be resumed as 2D.
# Usage: three_dimensions.sh SPHDISK [MPIEXEC]
set -uo pipefail
sphdisk=$1
mpiexec=${2:-}
config="$(dirname "$0")/small_ring.toml"
. "$(dirname "$0")/../lib/checks.sh"  # $work, ok, bad, finish
args=(-q --set problem.particles=3000 --set 'output.tau=[0.0185, 0.019]' --set sph.dimension=3
      --set 'physics.eos="locally_isothermal"' --set physics.aspect_ratio=0.05 --set physics.sound_speed_index=0.25
      --set 'integrator.scheme="block"' --set 'sph.pair_lists="rescan"')

same_snapshots() {  # $1, $2: run directories ($3: from snapshot_001 on, for a run whose first recorded another configuration)
  for f in ${3:-snapshot_000.hdf5} snapshot_001.hdf5 snapshot_002.hdf5; do cmp -s "$1/$f" "$2/$f" || return 1; done
}

OMP_NUM_THREADS=1 "$sphdisk" run "$config" "${args[@]}" -o "$work/t1" > /dev/null || bad "3D ring run (1 thread)"
OMP_NUM_THREADS=3 "$sphdisk" run "$config" "${args[@]}" -o "$work/t3" > /dev/null || bad "3D ring run (3 threads)"
if same_snapshots "$work/t1" "$work/t3"; then ok "3D: same snapshots with 1 and 3 threads"; else bad "3D: snapshots differ between 1 and 3 threads"; fi
# The other integrators and pair sources.
for variant in leapfrog,stored respa,stored rk45,rescan; do
  IFS=, read -r scheme storage <<< "$variant"
  for t in 1 3; do
    OMP_NUM_THREADS=$t "$sphdisk" run "$config" "${args[@]}" --set "integrator.scheme=\"$scheme\"" --set "sph.pair_lists=\"$storage\"" \
      -o "$work/$scheme$t" > /dev/null || bad "3D run with $scheme on $storage pairs ($t threads)"
  done
  if same_snapshots "$work/${scheme}1" "$work/${scheme}3"; then ok "3D, $scheme on $storage pairs: same snapshots with 1 and 3 threads"
  else bad "3D, $scheme on $storage pairs: snapshots differ between 1 and 3 threads"; fi
done

# Stopped by a SIGINT inside a block cycle (exit 75, checkpoint written inside it), then resumed
# (its snapshot_000 records the stop's key, so the snapshots after it are compared).
OMP_NUM_THREADS=2 "$sphdisk" run "$config" "${args[@]}" -o "$work/stopped" --set run.inject_interrupt_at_substep=5 > /dev/null 2>&1
rc=$?
if [ $rc -eq 75 ]; then ok "3D: a stop inside a block cycle exits 75"; else bad "3D: a stop inside a block cycle exited $rc, not 75"; fi
if [ -n "$mpiexec" ]; then
  cp -r "$work/stopped" "$work/stopped_mpi"
  "$mpiexec" -np 2 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 \
    "$sphdisk" resume "$work/stopped_mpi" -q --set run.inject_interrupt_at_substep=0 > /dev/null
  if same_snapshots "$work/t1" "$work/stopped_mpi" " "; then ok "3D: resumed on 2 ranks, the uninterrupted run's snapshots"
  else bad "3D: resumed on 2 ranks, snapshots differ from the uninterrupted run"; fi
  "$mpiexec" -np 3 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 \
    "$sphdisk" run "$config" "${args[@]}" -o "$work/r3" > /dev/null
  if same_snapshots "$work/t1" "$work/r3"; then ok "3D: same snapshots on 3 ranks as on one process"; else bad "3D: snapshots differ on 3 ranks"; fi
fi
OMP_NUM_THREADS=1 "$sphdisk" resume "$work/stopped" -q --set run.inject_interrupt_at_substep=0 > /dev/null
if same_snapshots "$work/t1" "$work/stopped" " "; then ok "3D: resumed, the uninterrupted run's snapshots"; else bad "3D: resumed, snapshots differ from the uninterrupted run"; fi
if out=$("$sphdisk" resume "$work/stopped" -q --set sph.dimension=2 2>&1); then bad "3D checkpoint resumed as 2D"
elif [ "$(printf '%s\n' "$out" | wc -l)" -eq 1 ] && [[ $out == *"sph.dimension cannot change"* ]]; then ok "3D checkpoint refused as 2D in one line"
else bad "3D checkpoint as 2D: unexpected message: $out"; fi

/usr/bin/python3 - "$work/t1/snapshot_001.hdf5" <<'EOF' && ok "3D snapshot: SimulationDimension 3, heights of the disc's thickness" || bad "3D snapshot layout"
import sys, h5py, numpy as np
with h5py.File(sys.argv[1]) as f:
    header = f["Header"].attrs
    z = f["PartType0/Coordinates"][:, 2] - header["PointMassPosition"][2]
    assert int(header["SimulationDimension"]) == 3 and int(header["Dimension"]) == 3
    assert 0.03 < np.sqrt(np.mean(z**2)) < 0.08, np.sqrt(np.mean(z**2))  # H = 0.05 r0 at the ring
EOF

# Eq. 6's conservative form keeps the angular momentum in 3D: on a thin ring (H/R = 0.005, kernels
# several scale heights tall) the net torque of the first evaluation's accelerations is 0.14% of the
# particles' own torques (its pair forces are not central), under the 1% asked. The default
# (consistent) form's is 44% there, falling as the kernels resolve the disc (docs/validation.md),
# and the run says in one line that they do not.
thin=(--set physics.aspect_ratio=0.005 --set 'output.tau=[0.0185]')
"$sphdisk" run "$config" "${args[@]}" "${thin[@]}" --set 'sph.viscous_force="conservative"' -o "$work/thin" > /dev/null 2>&1
/usr/bin/python3 - "$work/thin/snapshot_000.hdf5" <<'PYEOF' && ok "3D: no net torque from the conservative viscous force" || bad "3D: net torque of the conservative form"
import sys, h5py, numpy as np
with h5py.File(sys.argv[1]) as f:
    x = f["PartType0/Coordinates"][:] - f["Header"].attrs["PointMassPosition"]
    a, m = f["PartType0/Acceleration"][:], f["PartType0/Masses"][:]
torque = m * (x[:, 0] * a[:, 1] - x[:, 1] * a[:, 0])
print(f"net torque / sum |torque| = {abs(torque.sum()) / np.abs(torque).sum():.2e}")
assert abs(torque.sum()) < 1e-2 * np.abs(torque).sum()
PYEOF
out=$("$sphdisk" run "$config" "${args[@]}" "${thin[@]}" -o "$work/thin_default" 2>&1 > /dev/null)
if [ "$(printf '%s\n' "$out" | grep -c "warning: the kernels are taller than the disc: h > H")" -eq 1 ]; then
  ok "3D: one warning that the thin ring's kernels are taller than the disc"
else bad "3D: no single warning about the thin ring's vertical resolution: $out"; fi

out=$("$sphdisk" analyze "$work/t1/snapshot_002.hdf5")
if [[ $out == *"spreading rate: best-fit viscous time tau*/tau"* && $out == *"none in 3D"* ]]; then
  ok "3D: analyze compares the vertically integrated Sigma with the analytic ring"
else bad "3D: analyze output: $out"; fi
if /usr/bin/python3 "$(dirname "$0")/../python/test_yt_load.py" "$work/t1/snapshot_001.hdf5" > "$work/yt.log" 2>&1; then
  ok "3D snapshot: yt.load reads it right (tests/python/test_yt_load.py)"
else bad "3D snapshot in yt: $(grep -m3 FAIL "$work/yt.log")"; fi
# A 3D run from a 3D snapshot (problem.initial_conditions); the 2D run refuses it in one line.
if "$sphdisk" run "$config" -q --set sph.dimension=3 --set 'physics.eos="locally_isothermal"' --set physics.aspect_ratio=0.05 \
     --set "problem.initial_conditions=\"$work/t1/snapshot_001.hdf5\"" --set 'output.tau=[0.0192]' -o "$work/from_file" > /dev/null &&
   [ -e "$work/from_file/snapshot_001.hdf5" ]; then ok "3D: a run from a 3D snapshot"; else bad "3D: a run from a 3D snapshot failed"; fi
if out=$("$sphdisk" run "$config" -q --set "problem.initial_conditions=\"$work/t1/snapshot_001.hdf5\"" --set 'output.tau=[0.0192]' -o "$work/as_2d" 2>&1); then
  bad "a 3D snapshot run as 2D"
elif [[ $out == *"sph.dimension = 3"* ]]; then ok "a 3D snapshot as 2D initial conditions: refused, naming sph.dimension = 3"
else bad "a 3D snapshot as 2D: unexpected message: $out"; fi

# The power-law disc of configs/disc_phantom_like.toml (alpha viscosity), small and short.
disc=(-q --set problem.particles=3000 --set 'output.orbits=[0.02, 0.04]' "$(dirname "$0")/../../configs/disc_phantom_like.toml")
for t in 1 3; do OMP_NUM_THREADS=$t "$sphdisk" run "${disc[@]}" -o "$work/disc$t" > "$work/disc$t.out" || bad "3D disc run ($t threads)"; done
if grep -q "z_rms/R" "$work/disc1.out"; then ok "3D disc: the run ends with its profiles"; else bad "3D disc: no profiles at the run's end"; fi
if same_snapshots "$work/disc1" "$work/disc3"; then ok "3D disc: same snapshots with 1 and 3 threads"; else bad "3D disc: snapshots differ between 1 and 3 threads"; fi
# With the artificial viscosity (its limiter crosses the ranks with the stress; its signal speeds set steps).
for t in 1 3; do OMP_NUM_THREADS=$t "$sphdisk" run "${disc[@]}" --set physics.av_alpha=1 -o "$work/av$t" > /dev/null || bad "3D disc with AV ($t threads)"; done
if same_snapshots "$work/av1" "$work/av3"; then ok "3D disc, artificial viscosity: same snapshots with 1 and 3 threads"
else bad "3D disc, artificial viscosity: snapshots differ between 1 and 3 threads"; fi
if cmp -s "$work/disc1/snapshot_002.hdf5" "$work/av1/snapshot_002.hdf5"; then bad "3D disc: the artificial viscosity changed nothing"; fi
OMP_NUM_THREADS=2 "$sphdisk" run "${disc[@]}" --set physics.av_alpha=1 --set run.inject_interrupt_at_substep=1 -o "$work/av_stopped" > /dev/null 2>&1
OMP_NUM_THREADS=1 "$sphdisk" resume "$work/av_stopped" -q --set run.inject_interrupt_at_substep=0 > /dev/null
if same_snapshots "$work/av1" "$work/av_stopped" " "; then ok "3D disc, artificial viscosity: stopped inside a block cycle and resumed, the same snapshots"
else bad "3D disc, artificial viscosity: resumed run differs"; fi
if [ -n "$mpiexec" ]; then
  "$mpiexec" -np 3 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 "$sphdisk" run "${disc[@]}" --set physics.av_alpha=1 -o "$work/av_r3" > /dev/null
  if same_snapshots "$work/av1" "$work/av_r3"; then ok "3D disc, artificial viscosity: same snapshots on 3 ranks"
  else bad "3D disc, artificial viscosity: snapshots differ on 3 ranks"; fi
fi
out=$("$sphdisk" analyze "$work/disc1/snapshot_002.hdf5")
if [[ $out == *"Mdot_in"* && $out == *"z_rms/R"* && $out == *"mass budget"* && $out != *"spreading rate"* ]]; then
  ok "3D disc: analyze gives its radial profiles with the scale heights"
else bad "3D disc: analyze output: $out"; fi

if "$sphdisk" report "$work/t1" > /dev/null 2>&1 && grep -q "3D run: the particle" "$work/t1/report/report.md"; then
  ok "3D: sphdisk report draws the run, with each particle's column density"
else bad "3D: sphdisk report failed or did not say what its Sigma is"; fi
finish "three dimensions: "
