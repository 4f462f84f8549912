#!/usr/bin/env bash
# Outputs of two runs never mix: every snapshot records the run's identity (Header RunID, from the
# settings that decide the results); runs of the same settings share it, a resume keeps it, other
# settings change it, and `sphdisk report` refuses a directory holding snapshots of two runs. A resume
# that overrides settings continues the same run (its RunID kept, its report whole), a resume may not
# change the problem.* settings that made the particles (nor the central mass or the viscosity, which
# set the units and the clock), and a finished run is not resumed at all.
# Usage: run_identity.sh SPHDISK
set -uo pipefail
exe=$1
config="$(dirname "$0")/../validation/small_ring.toml"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
check() { if eval "$2"; then echo "ok   $1"; else echo "FAIL $1"; fail=1; fi; }
run_id() { /usr/bin/python3 -c "import h5py,sys; print(h5py.File(sys.argv[1])['Header'].attrs['RunID'].decode())" "$1"; }
common=(-q --set problem.particles=1500 --set 'output.tau=[0.0183, 0.0186]' --set output.progress_interval=0)

"$exe" run "$config" "${common[@]}" -o "$work/a" > /dev/null
"$exe" run "$config" "${common[@]}" -o "$work/b" --threads 1 --set checkpoint.every_steps=3 > /dev/null
"$exe" run "$config" "${common[@]}" -o "$work/c" --set problem.particles=1200 > /dev/null
"$exe" run "$config" "${common[@]}" -o "$work/d" --set run.max_steps=2 > /dev/null
"$exe" resume "$work/d" -q --set run.max_steps=0 > /dev/null
"$exe" run "$config" "${common[@]}" -o "$work/e" --set run.max_steps=2 > /dev/null
"$exe" run "$config" "${common[@]}" -o "$work/f" --set run.max_steps=2 > /dev/null
"$exe" resume "$work/e" -q --set run.max_steps=0 --set integrator.dt_max=5.0 > /dev/null
a0=$(run_id "$work/a/snapshot_000.hdf5")
check "RunID is 16 hex digits ($a0)" '[[ "$a0" =~ ^[0-9a-f]{16}$ ]]'
check "every snapshot of a run has the same RunID" '[ "$(run_id "$work/a/snapshot_002.hdf5")" = "$a0" ]'
check "the same settings on other threads, checkpoint cadence and directory: the same RunID" \
  '[ "$(run_id "$work/b/snapshot_002.hdf5")" = "$a0" ]'
check "a resumed run keeps its RunID" '[ "$(run_id "$work/d/snapshot_002.hdf5")" = "$a0" ]'
check "other particle numbers: another RunID" '[ "$(run_id "$work/c/snapshot_000.hdf5")" != "$a0" ]'
check "a resume that overrides an integrator setting keeps the RunID" \
  '[ "$(run_id "$work/e/snapshot_002.hdf5")" = "$(run_id "$work/e/snapshot_000.hdf5")" ]'
"$exe" report "$work/e" > /dev/null 2>&1
check "report of a run resumed with an override works" '[ -f "$work/e/report/report.md" ]'

# A resume that would change the particles' settings, or of a finished run: one line, exit 2, no file touched.
sums() { md5sum "$1"/* 2> /dev/null; }
before=$(sums "$work/a")
err=$("$exe" resume "$work/d" -q --set problem.particles=5000 2>&1 > /dev/null)
code=$?
check "resume --set problem.particles=... refused in one line naming the key (exit $code: $err)" \
  '[ $code -eq 2 ] && [ "$(wc -l <<< "$err")" -eq 1 ] && grep -q "problem.particles cannot change on resume" <<< "$err"'
before_f=$(sums "$work/f")
for key in physics.viscosity=6e-8 physics.central_mass=5; do
  err=$("$exe" resume "$work/f" -q --set "$key" 2>&1 > /dev/null)
  code=$?
  check "resume --set $key (the run's units or clock) refused in one line (exit $code: $err)" \
    '[ $code -eq 2 ] && [ "$(wc -l <<< "$err")" -eq 1 ] && grep -q "${key%%=*} cannot change on resume" <<< "$err"'
done
err=$("$exe" resume "$work/f" -q --set 'output.dir="elsewhere"' 2>&1 > /dev/null)
code=$?
check "resume --set output.dir refused in one line (exit $code: $err)" \
  '[ $code -eq 2 ] && [ "$(wc -l <<< "$err")" -eq 1 ] && grep -q "output.dir cannot change on resume" <<< "$err"'
check "and the run's files stay as they were" '[ "$(sums "$work/f")" = "$before_f" ]'
err=$("$exe" resume "$work/a" -q 2>&1 > /dev/null)
code=$?
check "resume of a finished run refused in one line naming the way on (exit $code: $err)" \
  '[ $code -eq 2 ] && [ "$(wc -l <<< "$err")" -eq 1 ] && grep -q "is complete" <<< "$err" && grep -q "output.tau" <<< "$err"'
check "and leaves its files as they were (timers.json, ranks.json, snapshots)" '[ "$(sums "$work/a")" = "$before" ]'

"$exe" report "$work/a" > /dev/null 2>&1
check "report of one run works" '[ -f "$work/a/report/report.md" ]'
cp "$work/c/snapshot_002.hdf5" "$work/a/snapshot_002.hdf5"
err=$("$exe" report "$work/a" 2>&1 > /dev/null)
code=$?
check "report refuses snapshots of two runs: exit non-zero, one line naming both (exit $code: $err)" \
  '[ $code -ne 0 ] && [ "$(wc -l <<< "$err")" -eq 1 ] && grep -q "snapshots of different runs" <<< "$err"'
exit $fail
