#!/usr/bin/env bash
# `sphdisk sweep` (remote tasks): a study of four short runs over 3 ranks (rank 0 manages, ranks 1
# and 2 run), one run failing on purpose: it must be retried on another rank and reported failed;
# the others must finish with their snapshots; a second sweep into the same output is refused
# without --overwrite; one process without mpirun runs the study too.
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

sed -i 's/output = "sweep_out"/output = "one_process"/' sweep_study.toml
OMP_NUM_THREADS=1 "$sphdisk" sweep sweep_study.toml > out3.txt 2> err3.txt
rc=$?
check "one process without mpirun runs the study (rc $rc)" '[ $rc -eq 5 ] && [ "$(grep -c ",ok,0," one_process/sweep.csv)" -eq 3 ]'
[ $fail -eq 0 ] && echo "sweep: passed" || echo "sweep: FAILED"
exit $fail
