#!/usr/bin/env bash
# Block-timestep runs shown, stopped and resumed inside their cycles, which can last hours in a large
# run. Progress lines come from inside a cycle. A block cycle's first partial evaluation reads the density
# and stress of the last full one, so checkpoints carry them (kRateState) and a resumed run must end
# with the particles of an uninterrupted one: after SIGKILL, after one stop signal inside a cycle
# (honoured when the cycle ends), after a second one (the cycle abandoned, the last checkpoint
# kept), and from a checkpoint written by two MPI ranks (when MPIEXEC is given). Signals inside a
# cycle are raised by the testing aid run.inject_interrupt_at_substep, so they land at a known tick.
# Usage: block_stop_resume.sh SPHDISK [MPIEXEC]
set -uo pipefail
sphdisk=$1
mpiexec=${2:-}
config="$(dirname "$0")/small_ring.toml"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# ~55 block cycles (~130 substeps) to tau = 0.030.
args=(--set problem.particles=4000 --set 'output.tau=[0.0186, 0.0300]' --set 'integrator.scheme="block"'
      --set output.progress_interval=0)
passed=0 failed=0
ok() { passed=$((passed + 1)); echo "ok   $1"; }
bad() { failed=$((failed + 1)); echo "FAIL $1"; }

OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$work/ref" "${args[@]}" > /dev/null || { echo "reference run failed"; exit 1; }

same_particles_as_reference() {
  for f in snapshot_001.hdf5 snapshot_002.hdf5; do h5diff -q "$work/ref/$f" "$1/$f" /PartType0 /PartType0 || return 1; done
}
checkpoint_step() {
  /usr/bin/python3 -c "import h5py,sys; print(int(h5py.File(sys.argv[1])['Checkpoint'].attrs['Step']))" "$1/checkpoint.hdf5" 2> /dev/null || echo none
}
# Runs into $work/$1 with the extra settings after it, stopped by injected signals: sets dir, rc,
# step (of its checkpoint) and err (its stderr's file).
stopped_run() {
  dir=$work/$1 err=$work/$1.err
  shift
  OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" "$@" > /dev/null 2> "$err"
  rc=$?
  step=$(checkpoint_step "$dir")
}
# Resumes run $1 (on $2 threads) without the injected signals (a resume missing the density and
# stress once hung: killed after two minutes).
resume() { OMP_NUM_THREADS=$2 timeout -s KILL 120 "$sphdisk" resume "$1" -q --set run.inject_interrupt_at_substep=0 > /dev/null; }

# Progress lines from inside the cycles (a line at every substep here).
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -o "$work/progress" "${args[@]}" --set output.progress_interval=1e-9 \
  --set run.max_steps=3 > /dev/null 2> "$work/progress.err"
inside=$(grep -c "into the step's block cycle" "$work/progress.err")
if [ "$inside" -gt 3 ]; then ok "progress lines inside block cycles ($inside in 3 cycles)"; else bad "progress inside cycles: $inside lines"; fi

# SIGKILL once the run has passed step 20 (checkpoints every 3 cycles); resumed on 1 thread.
dir=$work/kill
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" --set checkpoint.every_steps=3 > /dev/null 2>&1 &
pid=$!
for _ in $(seq 4000); do
  [ -e "$dir/checkpoint.hdf5" ] && [ "$(wc -l < "$dir/diagnostics.csv")" -gt 20 ] && break
  sleep 0.005
done
kill -9 $pid 2> /dev/null
wait $pid 2> /dev/null
rc=$?
step=$(checkpoint_step "$dir")
if [ $rc -eq 137 ] && OMP_NUM_THREADS=1 timeout -s KILL 120 "$sphdisk" resume "$dir" -q > /dev/null &&
   same_particles_as_reference "$dir"; then
  ok "block steps: SIGKILL after step 20 (checkpoint of step $step), resumed on 1 thread: the reference particles"
else
  bad "block steps: SIGKILL after step 20 (rc=$rc, 137 if killed mid-run; checkpoint of step $step)"
fi

# One signal inside a cycle: acknowledged at once, the cycle finished and checkpointed, exit 75.
stopped_run one --set run.inject_interrupt_at_substep=40
rows=$(($(wc -l < "$dir/diagnostics.csv") - 2))  # the last row's step (header, step 0)
if [ $rc -eq 75 ] && grep -q "stop requested" "$err" && grep -q "sphdisk resume" "$err" &&
   [ "$step" = "$rows" ]; then
  ok "one signal inside a cycle: acknowledged, the cycle ended with a checkpoint (step $step), exit 75"
else
  bad "one signal inside a cycle: rc=$rc, checkpoint of step $step, last diagnostics row $rows: $(cat "$err")"
fi
if resume "$dir" 3 && same_particles_as_reference "$dir"; then
  ok "one signal inside a cycle, resumed on 3 threads: the reference particles"
else
  bad "one signal inside a cycle: resume"
fi

# Two signals inside a cycle: the cycle abandoned unsaved, the last checkpoint (every cycle) kept.
stopped_run two --set checkpoint.every_steps=1 --set run.inject_interrupt_at_substep=60 --set run.inject_interrupts=2
if [ $rc -eq 75 ] && grep -q "not saved; continue from the checkpoint of step $step with: sphdisk resume" "$err"; then
  ok "two signals inside a cycle: abandoned, exit 75, the checkpoint of step $step kept"
else
  bad "two signals inside a cycle: rc=$rc, checkpoint of step $step: $(cat "$err")"
fi
if resume "$dir" 1 && same_particles_as_reference "$dir"; then
  ok "two signals inside a cycle, resumed on 1 thread: the reference particles"
else
  bad "two signals inside a cycle: resume"
fi

# Two signals before any checkpoint: nothing written but what was there; told to start again.
stopped_run early --set run.inject_interrupt_at_substep=2 --set run.inject_interrupts=2
if [ $rc -eq 75 ] && [ ! -e "$dir/checkpoint.hdf5" ] && grep -q "start the run again" "$err" &&
   h5diff -q "$work/ref/snapshot_000.hdf5" "$dir/snapshot_000.hdf5" /PartType0 /PartType0; then
  ok "two signals before any checkpoint: exit 75, no checkpoint, snapshot_000 intact, told to start again"
else
  bad "two signals before any checkpoint: rc=$rc: $(cat "$err")"
fi

# A checkpoint written by two ranks, resumed by one process.
if [ -n "$mpiexec" ]; then
  dir=$work/ranks
  "$mpiexec" -np 2 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 "$sphdisk" run "$config" -q -o "$dir" \
    "${args[@]}" --set run.inject_interrupt_at_substep=100 > /dev/null 2>&1
  step=$(checkpoint_step "$dir")
  if [ "$step" != none ] && resume "$dir" 2 && same_particles_as_reference "$dir"; then
    ok "a checkpoint of 2 ranks (step $step) resumed by one process on 2 threads: the reference particles"
  else
    bad "a checkpoint of 2 ranks (step $step) resumed by one process"
  fi
fi

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
