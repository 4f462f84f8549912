#!/usr/bin/env bash
# sph.neighbours = "auto" (the default) is resolved from the particles a run starts with, and the
# number goes into config.toml, the snapshots' /Parameters and the checkpoint, so that a resume
# continues with it: 20,000 generated particles give 85 (60 sqrt(2)), a file of them read as initial
# conditions 85 as well, a 3D run 60, and a number given is kept.
set -uo pipefail
sphdisk=$1
config="$(dirname "$0")/../../configs/ring_cold.toml"
. "$(dirname "$0")/../lib/checks.sh"  # $work, ok, bad, finish
one_step=(-q --set run.max_steps=1 --set output.progress_interval=0 --set checkpoint.every_seconds=0)
recorded() { grep -E '^neighbours = ' "$1/config.toml" | cut -d' ' -f3; }
param() { /usr/bin/python3 -c "import h5py,sys; print(h5py.File(sys.argv[1])['Parameters'].attrs['sph.neighbours'])" "$1" 2> /dev/null; }

"$sphdisk" run "$config" "${one_step[@]}" --set problem.particles=20000 -o "$work/a" > /dev/null
[ "$(recorded "$work/a")" = 85.0 ] && ok "20,000 particles: config.toml records 85" || bad "config.toml records '$(recorded "$work/a")' for 20,000 particles, not 85.0"
[ "$(param "$work/a/snapshot_001.hdf5")" = 85.0 ] && ok "the snapshot's /Parameters records 85" || bad "/Parameters sph.neighbours is '$(param "$work/a/snapshot_001.hdf5")'"
checked=$("$sphdisk" run "$config" --check --set problem.particles=20000 | grep -E '^neighbours = ' | cut -d' ' -f3)
[ "$checked" = 85.0 ] && ok "run --check prints the number the run will use, 85" || bad "run --check prints neighbours = '$checked'"
"$sphdisk" resume "$work/a" -q --set run.max_steps=2 > /dev/null
[ "$(recorded "$work/a")" = 85.0 ] && [ "$(param "$work/a/snapshot_001.hdf5")" = 85.0 ] &&
  ok "a resume keeps 85" || bad "after a resume: '$(recorded "$work/a")', '$(param "$work/a/snapshot_001.hdf5")'"

printf '[problem]\ninitial_conditions = "%s"\n[output]\ntimes = [100.0]\n' "$work/a/snapshot_000.hdf5" > "$work/ic.toml"
"$sphdisk" run "$work/ic.toml" "${one_step[@]}" -o "$work/b" > /dev/null
[ "$(recorded "$work/b")" = 85.0 ] && ok "a file of 20,000 particles: 85" || bad "a file of 20,000 particles gives '$(recorded "$work/b")'"

"$sphdisk" run "$config" "${one_step[@]}" --set problem.particles=2000 --set sph.dimension=3 -o "$work/c" > /dev/null 2>&1
[ "$(recorded "$work/c")" = 60.0 ] && ok "3D: 60" || bad "3D gives '$(recorded "$work/c")'"

"$sphdisk" run "$config" "${one_step[@]}" --set problem.particles=20000 --set sph.neighbours=57.9 -o "$work/d" > /dev/null
[ "$(recorded "$work/d")" = 57.9 ] && ok "a number given is kept" || bad "sph.neighbours = 57.9 gives '$(recorded "$work/d")'"
finish "auto_neighbours_recorded: "
