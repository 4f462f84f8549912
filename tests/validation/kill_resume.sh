#!/usr/bin/env bash
# Runs killed with SIGKILL at arbitrary moments, or stopped with SIGTERM, and resumed (with another
# thread count) must end with snapshots byte-identical to an uninterrupted run. A corrupted
# checkpoint must be refused with a one-line error.
set -uo pipefail
sphdisk=$1
config="$(dirname "$0")/small_ring.toml"
. "$(dirname "$0")/../lib/checks.sh"  # $work, ok, bad, finish
# ~490 leapfrog steps to tau = 0.030: long enough that every kill below lands mid-run (the kills wait
# for steps, not seconds, so a faster build or machine does not move them past the run's end). Block
# cycles, far fewer, are stopped and resumed by tests/validation/block_stop_resume.sh.
args=(--set problem.particles=4000 --set 'output.tau=[0.0186, 0.0300]' --set checkpoint.every_steps=7 --set output.progress_interval=0
      --set 'integrator.scheme="leapfrog"' --set 'sph.pair_lists="stored"')

OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$work/ref" "${args[@]}" > /dev/null || { echo "reference run failed"; exit 1; }

# Waits until the run in $1 has written its first checkpoint (something to resume from) and
# diagnostics of at least $2 steps (flushed just before each checkpoint is written).
wait_for_step() {
  for _ in $(seq 4000); do
    [ -e "$1/checkpoint.hdf5" ] && [ "$(wc -l < "$1/diagnostics.csv")" -gt "$2" ] && return 0
    sleep 0.005
  done
  return 1
}
# Sends signal $2 to run $1 and returns its exit status (128 + 9 when SIGKILL found it running).
kill_mid_run() {
  kill -"$2" "$1" 2> /dev/null
  wait "$1" 2> /dev/null
}

same_as_reference() {
  for f in snapshot_001.hdf5 snapshot_002.hdf5; do cmp -s "$work/ref/$f" "$1/$f" || return 1; done
}
# The same particle data (exact comparison), for runs whose stored configuration differs.
same_particles_as_reference() {
  for f in snapshot_001.hdf5 snapshot_002.hdf5; do h5diff -q "$work/ref/$f" "$1/$f" /PartType0 /PartType0 || return 1; done
}

# SIGKILL once the run has passed a step (several kill points, each landing at an arbitrary moment
# of a step: computing, writing a snapshot or a checkpoint).
for at in 7 20 60 150 300; do
  dir=$work/kill_$at
  OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" > /dev/null 2>&1 &
  pid=$!
  wait_for_step "$dir" $at
  kill_mid_run $pid 9
  rc=$?
  step=$(/usr/bin/python3 -c "import h5py,sys; print(int(h5py.File(sys.argv[1])['Checkpoint'].attrs['Step']))" "$dir/checkpoint.hdf5" 2>/dev/null || echo "?")
  if [ $rc -eq 137 ] && OMP_NUM_THREADS=1 "$sphdisk" resume "$dir" -q > /dev/null && same_as_reference "$dir"; then
    ok "SIGKILL after step $at (checkpoint of step $step), resumed on 1 thread: identical snapshots"
  else
    bad "SIGKILL after step $at (rc=$rc, 137 if killed mid-run; checkpoint of step $step)"
  fi
done

# Checkpoints by simulated time alone: one appears before the first output, and resuming from a
# kill still gives identical snapshots.
dir=$work/by_tau
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" --set checkpoint.every_steps=0 \
  --set checkpoint.every_seconds=0 --set checkpoint.every_tau=0.0001 > /dev/null 2>&1 &
pid=$!
for _ in $(seq 400); do [ -e "$dir/checkpoint.hdf5" ] && break; sleep 0.01; done
[ -e "$dir/snapshot_001.hdf5" ] && early=no || early=yes
wait_for_step "$dir" 100
kill_mid_run $pid 9
rc=$?
if [ $early = yes ] && [ $rc -eq 137 ] && OMP_NUM_THREADS=1 "$sphdisk" resume "$dir" -q > /dev/null && same_particles_as_reference "$dir"; then
  ok "checkpoint.every_tau: checkpoint before the first output; SIGKILL and resume: identical particle data"
else
  bad "checkpoint.every_tau (checkpoint before first output: $early; rc=$rc, 137 if killed mid-run)"
fi

# A NaN in the middle of a run (injected at step 30, checkpoints every 7 steps): exit 3, a debug
# dump, and the last good checkpoint (step 28) kept; resuming from it without the fault gives the
# reference particle data.
dir=$work/nan
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" --set run.inject_nan_at_step=30 > /dev/null 2> "$work/nan.err"
rc=$?
step=$(/usr/bin/python3 -c "import h5py,sys; print(int(h5py.File(sys.argv[1])['Checkpoint'].attrs['Step']))" "$dir/checkpoint.hdf5" 2>/dev/null || echo "?")
if [ $rc -eq 3 ] && grep -q "non-finite velocity of particle ID .* at step 30" "$work/nan.err" && [ -e "$dir/debug_step_30.hdf5" ] && [ "$step" = 28 ] &&
   OMP_NUM_THREADS=1 "$sphdisk" resume "$dir" -q --set run.inject_nan_at_step=0 > /dev/null && same_particles_as_reference "$dir"; then
  ok "NaN at step 30: exit 3, debug dump, checkpoint of step 28 kept and resumable to the reference"
else
  bad "NaN at step 30: rc=$rc checkpoint step=$step $(cat "$work/nan.err")"
fi

# SIGTERM: checkpoint, exit 75, resume.
dir=$work/term
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" > /dev/null 2> "$work/term.err" &
pid=$!
wait_for_step "$dir" 60
kill_mid_run $pid TERM
rc=$?
if [ $rc -eq 75 ] && grep -q "sphdisk resume" "$work/term.err"; then ok "SIGTERM: exit 75 with the resume command"; else bad "SIGTERM: rc=$rc $(cat "$work/term.err")"; fi
if OMP_NUM_THREADS=3 "$sphdisk" resume "$dir" -q > /dev/null && same_as_reference "$dir"; then ok "SIGTERM then resume on 3 threads: identical snapshots"; else bad "SIGTERM resume"; fi

# Without stored lists (sph.pair_lists = "rescan"): SIGKILL, then resume on another thread count.
rargs=("${args[@]}" --set 'sph.pair_lists="rescan"')
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$work/ref_rescan" "${rargs[@]}" > /dev/null
dir=$work/kill_rescan
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${rargs[@]}" > /dev/null 2>&1 &
pid=$!
wait_for_step "$dir" 100
kill_mid_run $pid 9
rc=$?
if [ $rc -eq 137 ] && OMP_NUM_THREADS=1 "$sphdisk" resume "$dir" -q > /dev/null &&
   cmp -s "$work/ref_rescan/snapshot_001.hdf5" "$dir/snapshot_001.hdf5" && cmp -s "$work/ref_rescan/snapshot_002.hdf5" "$dir/snapshot_002.hdf5"; then
  ok "rescanned pairs: SIGKILL, resumed on 1 thread: identical snapshots"
else
  bad "rescanned pairs: SIGKILL and resume (rc=$rc, 137 if killed mid-run)"
fi

# A corrupted checkpoint is refused, and nothing is written.
cp "$work/ref/checkpoint.hdf5" "$work/corrupt.hdf5"
size=$(stat -c %s "$work/corrupt.hdf5")
printf '\xff\xfe\xfd\xfc' | dd of="$work/corrupt.hdf5" bs=1 seek=$((size - 4096)) conv=notrunc status=none
mkdir -p "$work/c" && cp "$work/corrupt.hdf5" "$work/c/checkpoint.hdf5"
"$sphdisk" resume "$work/c" -q > /dev/null 2> "$work/c.err"
rc=$?
if [ $rc -eq 2 ] && [ "$(wc -l < "$work/c.err")" -eq 1 ] && [ ! -e "$work/c/snapshot_001.hdf5" ]; then ok "corrupt checkpoint refused: $(cat "$work/c.err")"; else bad "corrupt checkpoint: rc=$rc $(cat "$work/c.err")"; fi
"$sphdisk" resume "$work/none" -q > /dev/null 2> "$work/n.err"
rc=$?
if [ $rc -eq 2 ] && grep -q "no checkpoint" "$work/n.err"; then ok "missing checkpoint refused"; else bad "missing checkpoint: rc=$rc"; fi

finish "kill and resume: "
