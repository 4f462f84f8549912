#!/usr/bin/env bash
# Block-timestep runs shown, stopped and resumed inside their cycles, which can last hours in a large
# run. Progress lines come from inside a cycle. A block cycle's first partial evaluation reads the density
# and stress of the last full one, so checkpoints carry them (kRateState); a checkpoint written inside
# a cycle also carries the particles' steps in it (kStepState) and the cycle's state. A resumed run
# must end with the particles of an uninterrupted one: after SIGKILL (checkpoints at cycle ends, or
# inside cycles every so many seconds), after one stop signal inside a cycle (a checkpoint inside
# it), after a second one (the cycle abandoned, the last checkpoint kept), after a NaN inside a cycle
# (none stored), with the mixed gradient correction, and across rank counts inside a cycle (when
# MPIEXEC is given). Signals and the NaN
# inside a cycle come from the testing aids run.inject_interrupt_at_substep and
# run.inject_nan_at_substep, so they land at a known tick.
# Usage: block_stop_resume.sh SPHDISK [MPIEXEC]
set -uo pipefail
sphdisk=$1
mpiexec=${2:-}
config="$(dirname "$0")/small_ring.toml"
. "$(dirname "$0")/../lib/checks.sh"  # $work, ok, bad, finish
# ~55 block cycles (~130 substeps) to tau = 0.030.
args=(--set problem.particles=4000 --set 'output.tau=[0.0186, 0.0300]' --set 'integrator.scheme="block"'
      --set output.progress_interval=0)

OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$work/ref" "${args[@]}" > /dev/null || { echo "reference run failed"; exit 1; }

same_particles_as_reference() {
  for f in snapshot_001.hdf5 snapshot_002.hdf5; do h5diff -q "${2:-$work/ref}/$f" "$1/$f" /PartType0 /PartType0 || return 1; done
}
checkpoint_attr() {
  /usr/bin/python3 -c "import h5py,sys; print(int(h5py.File(sys.argv[1])['Checkpoint'].attrs[sys.argv[2]]))" "$1/checkpoint.hdf5" "$2" 2> /dev/null || echo none
}
checkpoint_step() { checkpoint_attr "$1" Step; }
inside_cycle() { [ "$(checkpoint_attr "$1" StepState)" = 1 ]; }
# diagnostics.csv without its wall-time column
diagnostics() { cut -d, -f1-11 "$1/diagnostics.csv"; }
# Runs into $work/$1 with the extra settings after it, stopped by injected signals: sets dir, rc,
# step (of its checkpoint) and err (its stderr's file).
stopped_run() {
  dir=$work/$1 err=$work/$1.err
  shift
  OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" "$@" > /dev/null 2> "$err"
  rc=$?
  step=$(checkpoint_step "$dir")
}
# Resumes run $1 (on $2 threads, with the settings after them) without the injected signals (a
# resume missing the density and stress once hung: killed after two minutes).
resume() {
  local dir=$1 threads=$2
  shift 2
  OMP_NUM_THREADS=$threads timeout -s KILL 120 "$sphdisk" resume "$dir" -q --set run.inject_interrupt_at_substep=0 "$@" > /dev/null
}

# Progress lines from inside the cycles (a line at every substep here).
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -o "$work/progress" "${args[@]}" --set output.progress_interval=1e-9 \
  --set run.max_steps=3 > /dev/null 2> "$work/progress.err"
inside=$(grep -c "into the step's block cycle" "$work/progress.err")
# (the first cycle's lines count the updates made in it: a 10M ring's first cycle is its whole run)
first=$(grep "^step 1 .*into the step's block cycle" "$work/progress.err" | grep -vc " 0 updates/s")
if [ "$inside" -gt 3 ] && [ "$first" -gt 0 ]; then
  ok "progress lines inside block cycles ($inside in 3 cycles; $first inside the first with its updates counted)"
else
  bad "progress inside cycles: $inside lines, $first in the first cycle with updates counted"
fi

# Runs into $work/$1 with the setting $2 and kills it with SIGKILL once it has passed step 20 and its
# checkpoint passes the test $3 (a command given the directory): sets dir, rc and step.
killed_run() {
  dir=$work/$1
  OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" --set "$2" > /dev/null 2>&1 &
  local pid=$!
  local deadline=$((SECONDS + 300))  # (a loaded CI machine writes checkpoints slowly)
  while [ $SECONDS -lt $deadline ] && kill -0 $pid 2> /dev/null; do
    # Looked at while the run is held (SIGSTOP), so that it is killed with the checkpoint seen.
    kill -STOP $pid 2> /dev/null
    [ -e "$dir/checkpoint.hdf5" ] && [ "$(wc -l 2> /dev/null < "$dir/diagnostics.csv" || echo 0)" -gt 20 ] && "$3" "$dir" && break
    kill -CONT $pid 2> /dev/null
    sleep 0.005
  done
  kill -9 $pid 2> /dev/null
  wait $pid 2> /dev/null
  rc=$?
  step=$(checkpoint_step "$dir")
}
resumed_on_one_thread() { resume "$1" 1 && same_particles_as_reference "$1"; }

# Checkpoints every 3 cycles; resumed on 1 thread.
killed_run kill checkpoint.every_steps=3 true
if [ $rc -eq 137 ] && resumed_on_one_thread "$dir"; then
  ok "block steps: SIGKILL after step 20 (checkpoint of step $step), resumed on 1 thread: the reference particles"
else
  bad "block steps: SIGKILL after step 20 (rc=$rc, 137 if killed mid-run; checkpoint of step $step)"
fi

# Checkpoints inside the cycles (every substep here: checkpoint.every_seconds), killed when the
# last one is inside a cycle; resumed on 1 thread.
killed_run kill_inside checkpoint.every_seconds=1e-9 inside_cycle
inside=$(checkpoint_attr "$dir" StepState)
if [ $rc -eq 137 ] && [ "$inside" = 1 ] && resumed_on_one_thread "$dir"; then
  ok "block steps: SIGKILL with checkpoints inside cycles (one inside step $((step + 1))'s cycle), resumed on 1 thread: the reference particles"
else
  bad "block steps: SIGKILL with checkpoints inside cycles (rc=$rc, 137 if killed mid-run; checkpoint of step $step, inside a cycle: $inside)"
fi

# One signal inside a cycle: a checkpoint inside the cycle at its next tick, exit 75.
stopped_run one --set run.inject_interrupt_at_substep=40
rows=$(($(wc -l < "$dir/diagnostics.csv") - 2))  # the last row's step (header, step 0)
if [ $rc -eq 75 ] && grep -q "stop requested: checkpoint written [0-9]*% into the block cycle of step $((step + 1))" "$err" &&
   grep -q "sphdisk resume" "$err" && [ "$step" = "$rows" ] && inside_cycle "$dir"; then
  ok "one signal inside a cycle: a checkpoint inside the cycle of step $((step + 1)), exit 75"
else
  bad "one signal inside a cycle: rc=$rc, checkpoint of step $step, last diagnostics row $rows: $(cat "$err")"
fi
# A resume of $dir with the setting $2 must be refused in one line containing $3, the checkpoint
# untouched ($1: what is tried).
refused() {
  local sum_before rc
  sum_before=$(md5sum < "$dir/checkpoint.hdf5")
  OMP_NUM_THREADS=1 "$sphdisk" resume "$dir" -q --set "$2" > /dev/null 2> "$work/refused.err"
  rc=$?
  if [ $rc -ne 0 ] && [ "$(wc -l < "$work/refused.err")" = 1 ] && grep -qF "$3" "$work/refused.err" &&
     [ "$(md5sum < "$dir/checkpoint.hdf5")" = "$sum_before" ]; then
    ok "a checkpoint inside a cycle resumed $1: refused in one line (rc=$rc), the checkpoint untouched"
  else
    bad "a checkpoint inside a cycle resumed $1: rc=$rc: $(cat "$work/refused.err")"
  fi
}
refused "with respa" 'integrator.scheme="respa"' 'integrator.scheme = "block"'
# An output halfway through the rest of the cycle.
mid=$(/usr/bin/python3 - "$dir" << 'EOF'
import csv, h5py, sys
attrs = h5py.File(sys.argv[1] + "/checkpoint.hdf5")["Checkpoint"].attrs
row = list(csv.DictReader(open(sys.argv[1] + "/diagnostics.csv")))[-1]  # the checkpoint's step
tau_per_time = float(row["tau"]) / float(row["time"])
print(repr(float(row["tau"]) + 0.5 * attrs["IntegratorState"][0] * tau_per_time))
EOF
)
refused "with an output inside that cycle (tau $mid)" "output.tau=[0.0186, $mid, 0.0300]" "inside a block cycle that ends at tau"
[ -n "$mpiexec" ] && cp -r "$dir" "$work/one_to_ranks"
if resume "$dir" 3 && same_particles_as_reference "$dir" && diff -q <(diagnostics "$work/ref") <(diagnostics "$dir") > /dev/null; then
  ok "one signal inside a cycle, resumed on 3 threads: the reference particles and diagnostics"
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
if resumed_on_one_thread "$dir"; then
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

# A NaN inside a cycle where a checkpoint is due (at every substep here): no checkpoint of it, but
# exit 3 with a debug dump; the last good checkpoint, resumed, gives the reference particles.
dir=$work/nan
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$dir" "${args[@]}" --set checkpoint.every_seconds=1e-9 \
  --set run.inject_nan_at_substep=40 > /dev/null 2> "$work/nan.err"
rc=$?
if [ $rc -eq 3 ] && grep -q "non-finite acceleration" "$work/nan.err" && ls "$dir"/debug_step_*.hdf5 > /dev/null 2>&1 &&
   resume "$dir" 1 --set run.inject_nan_at_substep=0 && same_particles_as_reference "$dir"; then
  ok "a NaN inside a cycle with a checkpoint due: exit 3, debug dump, the last good checkpoint resumed to the reference particles"
else
  bad "a NaN inside a cycle with a checkpoint due: rc=$rc: $(cat "$work/nan.err")"
fi

# Explicit kicks (integrator.viscous_update = "explicit"; the runs above take the default
# super-steps: a velocity at each step's start, no opening kick, the same fields with another
# meaning): one signal inside a cycle, resumed on 3 threads, gives the particles of an uninterrupted
# run with kicks; resumed with super-steps, it is refused.
kicks=("${args[@]}" --set 'integrator.viscous_update="explicit"')
OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$work/kicks_ref" "${kicks[@]}" > /dev/null ||
  bad "explicit kicks: the uninterrupted run failed"
default_args=("${args[@]}")
args=("${kicks[@]}")
stopped_run kicks --set run.inject_interrupt_at_substep=40
refused "with super-steps after explicit kicks" 'integrator.viscous_update="super_steps"' 'integrator.viscous_update = "explicit"'
if [ $rc -eq 75 ] && inside_cycle "$dir" && resume "$dir" 3 && same_particles_as_reference "$dir" "$work/kicks_ref"; then
  ok "explicit kicks: one signal inside a cycle, resumed on 3 threads: the uninterrupted run's particles"
else
  bad "explicit kicks: one signal inside a cycle (rc=$rc, checkpoint of step $step): resume"
fi
args=("${default_args[@]}")

# With the mixed gradient correction (its per-particle shift is checkpointed with the rate state) and
# with the scatter density (checkpointed with it too: the first partial evaluation after a resume
# reads the inactive particles' values): one signal inside a cycle, resumed on 3 threads, gives the
# particles of an uninterrupted run.
while IFS='|' read -r name label setting <&3; do
  variant=("${default_args[@]}" --set "$setting")
  OMP_NUM_THREADS=2 "$sphdisk" run "$config" -q -o "$work/${name}_ref" "${variant[@]}" > /dev/null ||
    bad "$label: the uninterrupted run failed"
  args=("${variant[@]}")
  stopped_run "$name" --set run.inject_interrupt_at_substep=40
  if [ $rc -eq 75 ] && inside_cycle "$dir" && resume "$dir" 3 && same_particles_as_reference "$dir" "$work/${name}_ref"; then
    ok "$label: one signal inside a cycle, resumed on 3 threads: the uninterrupted run's particles"
  else
    bad "$label: one signal inside a cycle (rc=$rc, checkpoint of step $step): resume"
  fi
done 3<<'VARIANTS'
mixed|mixed correction|sph.gradient_correction="mixed"
scatter|scatter density|sph.pair_density="scatter"
VARIANTS
args=("${default_args[@]}")

# Across rank counts inside a cycle: a checkpoint written by two ranks resumed by one process, and
# one written by one process resumed by two ranks.
if [ -n "$mpiexec" ]; then
  mpirun2() { "$mpiexec" -np 2 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 "$sphdisk" "$@"; }
  dir=$work/ranks
  mpirun2 run "$config" -q -o "$dir" "${args[@]}" --set run.inject_interrupt_at_substep=100 > /dev/null 2>&1
  step=$(checkpoint_step "$dir")
  if [ "$step" != none ] && inside_cycle "$dir" && resume "$dir" 2 && same_particles_as_reference "$dir"; then
    ok "a checkpoint of 2 ranks inside the cycle of step $((step + 1)) resumed by one process on 2 threads: the reference particles"
  else
    bad "a checkpoint of 2 ranks (step $step) resumed by one process"
  fi
  dir=$work/one_to_ranks
  step=$(checkpoint_step "$dir")
  if inside_cycle "$dir" && timeout -s KILL 120 "$mpiexec" -np 2 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 \
       "$sphdisk" resume "$dir" -q --set run.inject_interrupt_at_substep=0 > /dev/null 2>&1 && same_particles_as_reference "$dir"; then
    ok "a checkpoint of one process inside the cycle of step $((step + 1)) resumed by 2 ranks: the reference particles"
  else
    bad "a checkpoint of one process inside a cycle resumed by 2 ranks"
  fi
fi

finish ""
