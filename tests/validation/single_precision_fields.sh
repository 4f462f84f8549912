#!/usr/bin/env bash
# The build with SPHDISK_SINGLE_PRECISION_FIELDS (preset "single": density and the stress and
# moment-correction tensors stored as float, all sums in double): its unit tests pass, its
# results do not depend on the thread count, its stored densities are in fact single precision,
# a short ring run stays within single-precision rounding of the default (double) build's, and it
# passes kill_resume.sh, block_stop_resume.sh and, with MPIEXEC, rank_identity.sh (same bits for any
# rank count).
# Usage: single_precision_fields.sh PATH/TO/DOUBLE/sphdisk [MPIEXEC]   (builds build/single)
set -euo pipefail
double_exe=$(realpath "$1")
mpiexec=${2:-}
cd "$(dirname "$0")/../.."
cmake --preset single > /dev/null
cmake --build --preset single --target sphdisk unit_tests > /dev/null
build/single/tests/unit_tests --gtest_brief=1
single_exe=$PWD/build/single/sphdisk
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() {  # exe threads dir
  OMP_NUM_THREADS=$2 "$1" run -q --output "$work/$3" --set problem.particles=4000 \
    --set 'output.tau=[0.0185, 0.019]' --set output.progress_interval=0 tests/validation/small_ring.toml > /dev/null
}
run "$double_exe" 2 double
run "$single_exe" 1 single1
run "$single_exe" 3 single3
fail=0
for f in snapshot_001.hdf5 snapshot_002.hdf5; do
  if cmp -s "$work/single1/$f" "$work/single3/$f"; then echo "identical: $f of the single build with 1 and 3 threads"
  else echo "DIFFERENT: $f of the single build with 1 and 3 threads"; fail=1; fi
done
/usr/bin/python3 - "$work/double" "$work/single1" <<'PY' || fail=1
import sys
import h5py
import numpy as np

double_dir, single_dir = sys.argv[1:]
ok = True
with h5py.File(f"{double_dir}/snapshot_002.hdf5") as fd, h5py.File(f"{single_dir}/snapshot_002.hdf5") as fs:
    d, s = fd["PartType0"], fs["PartType0"]
    rho_d, rho_s = d["Density"][:], s["Density"][:]
    # The option takes effect: every stored density of the single build is a float, while the
    # double build's are not (its densities carry more than 24 significant bits).
    single_floats = np.all(rho_s == rho_s.astype(np.float32).astype(np.float64))
    double_floats = np.mean(rho_d == rho_d.astype(np.float32).astype(np.float64))
    print(f"single build: all densities floats: {single_floats}; double build: {double_floats:.3f} of them floats")
    ok &= bool(single_floats) and double_floats < 0.01
    flags = [int(f["Header"].attrs["SinglePrecisionFields"]) for f in (fd, fs)]
    print(f"Header SinglePrecisionFields: double build {flags[0]}, single build {flags[1]}")
    ok &= flags == [0, 1]
    # Within rounding of the default build: the viscous terms differ by ~6e-8 relative per
    # evaluation, the viscous acceleration is ~1e-3 of gravity here, over ~60 steps.
    h = np.median(d["SmoothingLength"][:])
    # Positions relative to the central mass (Header PointMassPosition: the box centre, which depends
    # on the particles' extent and may differ between the builds).
    x_d, x_s = (f["PartType0/Coordinates"][:] - f["Header"].attrs["PointMassPosition"] for f in (fd, fs))
    dx = np.max(np.abs(x_d - x_s)) / h
    drho = np.max(np.abs(rho_s / rho_d - 1))
    dv = np.max(np.abs(d["Velocities"][:] - s["Velocities"][:]))
    print(f"largest differences from the double build: position {dx:.2e} h, velocity {dv:.2e}, density {drho:.2e} relative")
    ok &= dx < 1e-7 and dv < 1e-8 and drho < 1e-6
sys.exit(0 if ok else 1)
PY
# Killed and resumed runs continue bit for bit in this build too.
if out=$(tests/validation/kill_resume.sh "$single_exe" 2>&1); then echo "single build: $(echo "$out" | tail -1)"
else echo "$out"; echo "single build: kill and resume FAILED"; fail=1; fi
# So do block-timestep runs, whose checkpoints hold the float density and tensors widened to double.
if out=$(tests/validation/block_stop_resume.sh "$single_exe" $mpiexec 2>&1); then echo "single build: $(echo "$out" | tail -1)"
else echo "$out"; echo "single build: block cycles stopped and resumed FAILED"; fail=1; fi
if [ -n "$mpiexec" ]; then
  if out=$(tests/validation/rank_identity.sh "$single_exe" "$mpiexec" 2>&1); then echo "single build: $(echo "$out" | tail -1)"
  else echo "$out"; echo "single build: rank identity FAILED"; fail=1; fi
fi
exit $fail
