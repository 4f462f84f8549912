#!/usr/bin/env bash
# The ring with one smoothing length for all (sph.smoothing = "constant", P98 sec. 5.3) and the
# default viscous force, which is then eq. 6's conservative form (sph.viscous_force = "auto";
# docs/validation.md, "One smoothing length for all"): 10,000 particles to tau = 0.0225 and 0.09.
# Checks that no particle leaves the ring (none beyond 2 r0 at tau = 0.0225, fewer than 0.1% at
# 0.09), the best-fit viscous time tau*/tau (0.92-1.08 at 0.09) and the annulus-mass L1 (<= 3x its
# sampling floor). With the consistent form the same run threw particles out to 24 r0 by tau =
# 0.0225 and 501 of them beyond 2 r0 by 0.09 (tau*/tau 0.80, L1 4.4x the floor; measured 2026-12-05).
# Usage: constant_h_ring.sh SPHDISK WORKDIR [--set KEY=VALUE ...]
set -euo pipefail
exe=$1
work=$2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
dir=$work/constant_h
"$exe" run "$here/../../configs/ring.toml" -q --overwrite -o "$dir" -t 2 --set problem.particles=10000 \
  --set 'sph.smoothing="constant"' --set 'output.tau=[0.0225, 0.09]' "${@:3}" > /dev/null
"$exe" analyze "$dir/snapshot_002.hdf5" --json "$dir/analysis.json" > /dev/null
/usr/bin/python3 - "$dir" <<'PY'
import json, sys
import h5py, numpy as np
d = sys.argv[1]
def beyond(snapshot, radius):
    with h5py.File(f"{d}/{snapshot}", "r") as f:
        x = f["PartType0/Coordinates"][:, :2] - f["Header"].attrs["BoxSize"][:2] / 2
        return int((np.hypot(x[:, 0], x[:, 1]) > radius).sum()), len(x)
early, n = beyond("snapshot_001.hdf5", 2.0)
late, n = beyond("snapshot_002.hdf5", 2.0)
a = json.load(open(f"{d}/analysis.json"))
ratio, l1, floor = a["tau_fit"] / a["tau"], a["mass_sigma_l1"], a["sampling_floor"]
ok = early == 0 and late < 0.001 * n and 0.92 <= ratio <= 1.08 and l1 <= 3.0 * floor
print(f"one h: beyond 2 r0 {early} particles at tau 0.0225 (need 0), {late} at 0.09 (need < {0.001 * n:.0f}); "
      f"tau*/tau = {ratio:.3f} (need 0.92-1.08); annulus-mass L1 {l1:.4f} = {l1 / floor:.2f} x the floor "
      f"(need <= 3): {'ok' if ok else 'FAIL'}")
sys.exit(0 if ok else 1)
PY
