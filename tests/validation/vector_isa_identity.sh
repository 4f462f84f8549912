#!/usr/bin/env bash
# Same input, same bits on every vector path: a short ring run with run.vector_isa = "auto" (the
# CPU's widest: AVX-512 or AVX2 on x86-64), "avx2" and "baseline" must give identical particle data
# in every snapshot (the /Parameters group differs: it records the setting), with leapfrog and with
# block timesteps (partial evaluations), with adaptive h and with one constant h (its own density
# loop), with pairs searched anew by every pair loop (sph.pair_lists = "rescan"), in 3D (its own
# candidate scan) with block steps and rescanned pairs, and ranks.json must name the path that ran. On a CPU
# without AVX2 all three run the baseline path, which the test then says.
set -euo pipefail
sphdisk=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for variant in leapfrog block leapfrog-constant block-rescan block-3d; do
  scheme=${variant%%-*}
  smoothing=adaptive
  storage=stored
  extra=()
  case $variant in
    *-constant) smoothing=constant ;;
    *-rescan) storage=rescan ;;
    *-3d) storage=rescan
          extra=(--set sph.dimension=3 --set 'physics.eos="locally_isothermal"' --set physics.aspect_ratio=0.02) ;;
  esac
  for isa in auto avx2 baseline; do
    "$sphdisk" run -q --output "$work/$variant-$isa" -t 2 \
      --set problem.particles=4000 --set 'output.tau=[0.0185, 0.019]' --set output.progress_interval=0 \
      --set "integrator.scheme=\"$scheme\"" --set "sph.smoothing=\"$smoothing\"" --set "sph.pair_lists=\"$storage\"" --set "run.vector_isa=\"$isa\"" \
      "${extra[@]}" "$(dirname "$0")/small_ring.toml" > /dev/null
  done
done
/usr/bin/python3 - "$work" <<'PY'
import glob, json, os, sys
import h5py
import numpy as np
work = sys.argv[1]
fail = 0
for scheme in ("leapfrog", "block", "leapfrog-constant", "block-rescan", "block-3d"):
    ran = {isa: json.load(open(f"{work}/{scheme}-{isa}/ranks.json"))[0]["vector_isa"] for isa in ("auto", "avx2", "baseline")}
    print(f"{scheme}: vector paths that ran: {ran}")
    if ran["baseline"] != "baseline" or ran["avx2"] not in ("avx2", "baseline") or ran["auto"] == "":
        print("WRONG vector path recorded"); fail = 1
    snaps = sorted(os.path.basename(f) for f in glob.glob(f"{work}/{scheme}-auto/snapshot_*.hdf5"))
    if len(snaps) != 3:
        print(f"expected 3 snapshots, found {snaps}"); fail = 1
    for isa in ("avx2", "baseline"):
        for s in snaps:
            with h5py.File(f"{work}/{scheme}-auto/{s}") as a, h5py.File(f"{work}/{scheme}-{isa}/{s}") as b:
                names = list(a["PartType0"].keys())
                same = all(np.array_equal(a["PartType0"][k][...].view(np.uint8), b["PartType0"][k][...].view(np.uint8)) for k in names)
                same &= names == list(b["PartType0"].keys())
            print(f"{'identical' if same else 'DIFFERENT'}: {scheme} {s} particle data, {ran['auto']} vs {ran[isa]}")
            fail |= not same
print(f"vector path identity: {0 if fail else 1} passed, {1 if fail else 0} failed")
sys.exit(1 if fail else 0)
PY
