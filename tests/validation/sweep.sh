#!/usr/bin/env bash
# `sphdisk sweep` (remote tasks): a study of four short runs over 3 ranks (rank 0 manages, ranks 1
# and 2 run), one run failing on purpose: it must be retried on another rank and reported failed;
# the others must finish with their snapshots; a second sweep into the same output is refused
# without --overwrite; a study stopped by SIGTERM keeps its record and exits 75; one process without
# mpirun runs the study too.
# Usage: sweep.sh SPHDISK MPIEXEC
set -uo pipefail
sphdisk=$1
mpiexec=$2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$here/sweep_study.toml" "$here/small_ring.toml" "$work/"
cd "$work"
fail=0
check() { if eval "$2"; then echo "ok   $1"; else echo "FAIL $1"; fail=1; fi; }

"$mpiexec" -np 3 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 "$sphdisk" sweep sweep_study.toml > out.txt 2> err.txt
rc=$?
check "exit code 5 when a run failed (got $rc)" '[ $rc -eq 5 ]'
check "summary line" 'grep -q "sweep: 4 runs, 3 succeeded, 1 failed" out.txt'
csv=sweep_out/sweep.csv
check "three runs ok" '[ "$(grep -c ",ok," $csv)" -eq 3 ]'
check "the failing run retried, then failed" 'grep -q "^fails,retried,.*,1," $csv && grep -q "^fails,failed,.*,2," $csv'
r1=$(grep "^fails,retried" $csv | cut -d, -f3); r2=$(grep "^fails,failed" $csv | cut -d, -f3)
check "the retry ran on another rank ($r1 then $r2)" '[ "$r1" != "$r2" ]'
check "work spread over both worker ranks" '[ "$(cut -d, -f3 $csv | tail -n +2 | sort -u | tr -d "\n")" = "12" ]'
check "each successful run wrote its snapshots" '[ -f sweep_out/N2000/snapshot_001.hdf5 ] && [ -f sweep_out/N3000/snapshot_001.hdf5 ] && [ -f sweep_out/N2000_rk45/snapshot_001.hdf5 ]'

"$mpiexec" -np 2 --oversubscribe --allow-run-as-root "$sphdisk" sweep sweep_study.toml > out2.txt 2> err2.txt
rc=$?
check "a second sweep into the same output is refused (rc $rc)" '[ $rc -ne 0 ] && grep -q "already holds results; use another output, or --overwrite" err2.txt'
check "the first sweep's results are untouched" '[ "$(grep -c ",ok," $csv)" -eq 3 ]'

# SIGTERM to every rank (as a batch system sends at its time limit) once a short run is done and two
# long ones run: both checkpoint, the queued run never starts, sweep.csv keeps every row, and the
# study exits 75.
printf 'base = "small_ring.toml"\noutput = "stopped"\nattempts = 1\n' > stop_study.toml
for run in "short 1000 0.0185" "long_a 8000 0.09" "long_b 8000 0.09" "never 1000 0.0185"; do
  read -r name n tau <<< "$run"
  printf '[[run]]\nname = "%s"\nset = ["problem.particles=%s", "output.tau=[%s]", "output.progress_interval=0"]\n' "$name" "$n" "$tau" >> stop_study.toml
done
"$mpiexec" -np 3 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 "$sphdisk" sweep stop_study.toml > out4.txt 2> err4.txt &
farm=$!
for _ in $(seq 1 240); do  # until the short run is reported and long_b has started
  [ "$(grep -c ",ok," stopped/sweep.csv 2> /dev/null)" = 1 ] && [ -f stopped/long_b/snapshot_000.hdf5 ] && break
  sleep 0.5
done
pkill -TERM -P "$farm"  # the ranks, not mpirun
wait $farm
rc=$?
check "a SIGTERM to every rank: the study exits 75 (got $rc)" '[ $rc -eq 75 ]'
check "sweep.csv keeps the finished run and the two stopped ones, which name their resume" \
  'grep -q "^short,ok," stopped/sweep.csv && grep -q "^long_a,failed,.*sphdisk resume" stopped/sweep.csv && grep -q "^long_b,failed,.*sphdisk resume" stopped/sweep.csv'
check "the queued run never starts; the stopped ones have their checkpoints" \
  '! grep -q "^never," stopped/sweep.csv && [ ! -e stopped/never ] && [ -f stopped/long_a/checkpoint.hdf5 ] && [ -f stopped/long_b/checkpoint.hdf5 ]'

sed -i 's/output = "sweep_out"/output = "one_process"/' sweep_study.toml
OMP_NUM_THREADS=1 "$sphdisk" sweep sweep_study.toml > out3.txt 2> err3.txt
rc=$?
check "one process without mpirun runs the study (rc $rc)" '[ $rc -eq 5 ] && [ "$(grep -c ",ok,0," one_process/sweep.csv)" -eq 3 ]'
[ $fail -eq 0 ] && echo "sweep: passed" || echo "sweep: FAILED"
exit $fail
