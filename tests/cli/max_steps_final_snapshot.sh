#!/usr/bin/env bash
# A run stopped by run.max_steps ends with a snapshot of its state and a checkpoint. The snapshot
# takes the number of the next output (its Header the time and step of the stop), `analyze` and
# `report` read it, and `resume` replaces it when it reaches that output, so a run continued to the
# end, in one resume or several, has the snapshots of a run straight through. A stop at an output
# time adds no snapshot.
set -uo pipefail
sphdisk=$1
config="$(dirname "$0")/../validation/small_ring.toml"
. "$(dirname "$0")/../lib/checks.sh"  # $work, ok, bad, finish
# Output 1 is reached at step 5 and output 2 at step 10 (checked on the reference run).
# The leapfrog: its steps, not block cycles, are what the step counts below assume.
small=(--set problem.particles=500 --set 'output.tau=[0.0182, 0.0184]' --set output.progress_interval=0
       --set 'integrator.scheme="leapfrog"')
run() { "$sphdisk" run -q "$config" "${small[@]}" "$@"; }
# attr FILE GROUP NAME: one attribute's value.
attr() { /usr/bin/python3 -c "import h5py,sys; print(h5py.File(sys.argv[1])[sys.argv[2]].attrs[sys.argv[3]])" "$@" 2> /dev/null; }
same_as_reference() {
  for k in 001 002; do
    h5diff -q "$work/ref/snapshot_$k.hdf5" "$1/snapshot_$k.hdf5" /PartType0 /PartType0 &&
      [ "$(attr "$1/snapshot_$k.hdf5" Header Step)" = "$(attr "$work/ref/snapshot_$k.hdf5" Header Step)" ] || return 1
  done
}

run -o "$work/ref" > /dev/null || { echo "reference run failed"; exit 1; }
[ "$(attr "$work/ref/snapshot_001.hdf5" Header Step)" = 5 ] && [ "$(attr "$work/ref/snapshot_002.hdf5" Header Step)" = 10 ] ||
  { echo "the reference's outputs are not at steps 5 and 10: adjust this test"; exit 1; }

# Stopped before output 1: snapshot_001 holds the state of step 2, as the checkpoint does.
dir=$work/stop2
run --set run.max_steps=2 -o "$dir" > "$work/out" 2> "$work/err"
rc=$?
snap=$dir/snapshot_001.hdf5
if [ $rc -eq 0 ] && [ "$(attr "$snap" Header Step)" = 2 ] && [ "$(attr "$dir/checkpoint.hdf5" Checkpoint Step)" = 2 ] &&
   [ "$(attr "$snap" Header Time)" = "$(attr "$dir/checkpoint.hdf5" Checkpoint Time)" ] && [ ! -e "$dir/snapshot_002.hdf5" ] &&
   grep -q "^stopped by run.max_steps at step 2" "$work/err"; then
  ok "run.max_steps=2: snapshot_001 and the checkpoint hold step 2 (time $(attr "$snap" Header Time)); with -q the stop is still said"
else
  bad "run.max_steps=2: rc=$rc; files: $(ls "$dir" 2> /dev/null) $(cat "$work/err")"
fi
if "$sphdisk" analyze "$snap" > "$work/analyze" 2>&1 && grep -q "^# tau = 0.0180" "$work/analyze" &&
   "$sphdisk" report "$dir" > /dev/null 2>&1 && [ -s "$dir/report/report.md" ]; then
  ok "analyze and report read the snapshot of the stop"
else
  bad "analyze / report of the stopped run: $(head -3 "$work/analyze")"
fi
if "$sphdisk" resume -q "$dir" --set run.max_steps=0 > /dev/null 2> "$work/err" && same_as_reference "$dir" &&
   "$sphdisk" report "$dir" > /dev/null 2>&1; then
  ok "resumed to the end: snapshot_001 replaced by output 1; both outputs as in the reference; report works"
else
  bad "resume to the end: $(cat "$work/err")"
fi

# Stopped between the outputs: the last output's number holds the stop, and the run does not
# print the accuracy table (that belongs to the last output).
dir=$work/stop7
run --set run.max_steps=7 -o "$dir" > "$work/out" 2> /dev/null
if [ "$(attr "$dir/snapshot_001.hdf5" Header Step)" = 5 ] && [ "$(attr "$dir/snapshot_002.hdf5" Header Step)" = 7 ] &&
   [ ! -s "$work/out" ]; then
  ok "run.max_steps=7: snapshot_001 is output 1, snapshot_002 step 7, no accuracy table"
else
  bad "run.max_steps=7: steps $(attr "$dir/snapshot_001.hdf5" Header Step), $(attr "$dir/snapshot_002.hdf5" Header Step); stdout $(head -1 "$work/out")"
fi

# Stopped at an output: nothing beyond it.
dir=$work/stop5
run --set run.max_steps=5 -o "$dir" > /dev/null 2> "$work/err"
if [ "$(attr "$dir/snapshot_001.hdf5" Header Step)" = 5 ] && [ "$(attr "$dir/checkpoint.hdf5" Checkpoint Step)" = 5 ] &&
   [ ! -e "$dir/snapshot_002.hdf5" ] && grep -q "state in $dir/snapshot_001.hdf5 and checkpoint.hdf5" "$work/err"; then
  ok "run.max_steps=5 (the step of output 1): no further snapshot, and the stop names snapshot_001 as the state's"
else
  bad "run.max_steps=5: files $(ls "$dir"); $(cat "$work/err")"
fi

# A chain of resumes of 3 steps each (run.max_steps stays in the stored configuration); once the
# run is finished a further resume is refused.
dir=$work/chain
run --set run.max_steps=3 -o "$dir" > /dev/null 2>&1
steps=()
for _ in 1 2 3 4; do
  "$sphdisk" resume -q "$dir" > /dev/null 2>&1 || break
  steps+=("$(attr "$dir/checkpoint.hdf5" Checkpoint Step)")
done
if [ "${steps[*]}" = "6 9 10" ] && same_as_reference "$dir"; then
  ok "resumes of 3 steps each (checkpoints at steps ${steps[*]}, the fourth refused: the run is complete): the reference's outputs"
else
  bad "chain of resumes: checkpoints at steps ${steps[*]}"
fi

finish "max_steps final snapshot: "
