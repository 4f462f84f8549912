#!/usr/bin/env bash
# run.log: each `run` and `resume` adds its command line, code version, build, ranks, threads and
# start time, then every line it prints on the terminal (progress, summary, errors; with --quiet
# too). `resume` appends after a line naming it; `--overwrite` starts a new log; a run killed with
# SIGKILL leaves all it wrote; over MPI ranks one process writes it.
set -uo pipefail
sphdisk=$1
mpiexec=${2:-}
config="$(dirname "$0")/../validation/small_ring.toml"
. "$(dirname "$0")/../lib/checks.sh"  # $work, ok, bad, finish
# The leapfrog: its steps, not block cycles, are what the counts below assume.
small=(--set problem.particles=500 --set 'output.tau=[0.0182, 0.0184]' --set output.progress_interval=1e-9
       --set 'integrator.scheme="leapfrog"')
version=$("$sphdisk" --version | sed -n '1s/^sphdisk //p')
options=$("$sphdisk" --version | sed -n '2s/^build: //p')
count() { grep -c -- "$1" "$2"; }

# A run stopped after 3 steps, on 2 threads: the header, and every line of the terminal.
dir=$work/run
OMP_NUM_THREADS=2 "$sphdisk" run "$config" "${small[@]}" --set run.max_steps=3 -o "$dir" > /dev/null 2> "$work/err"
log=$dir/run.log
missing=$(grep -vxFf "$log" "$work/err")
if head -1 "$log" | grep -q "^==== sphdisk run, started [0-9-]*T[0-9:]*[+-][0-9]* ====$" &&
   grep -qxF "command: $sphdisk run $config --set problem.particles=500 --set 'output.tau=[0.0182, 0.0184]' --set output.progress_interval=1e-9 --set 'integrator.scheme=\"leapfrog\"' --set run.max_steps=3 -o $dir" "$log" &&
   grep -qxF "working directory: $(pwd -P)" "$log" && grep -qxF "code version: $version" "$log" &&
   grep -qxF "build: $options" "$log" && grep -q "^ranks: 1, threads: 2 per rank, vector loops: " "$log" &&
   [ -s "$work/err" ] && [ -z "$missing" ] && [ "$(count '^step [0-9]' "$log")" = 3 ] && [ "$(count '^done: 3 steps' "$log")" = 1 ]; then
  ok "run: header, progress lines and summary, every terminal line"
else
  bad "run: terminal lines not in the log: '$missing'; log: $(cat "$log")"
fi

# Resumed with --quiet on 1 thread: appended after a line naming the resume, progress and summary included.
cp "$log" "$work/before"
OMP_NUM_THREADS=1 "$sphdisk" resume "$dir" -q --set run.max_steps=0 > /dev/null 2>&1
size=$(stat -c %s "$work/before")
if cmp -s "$work/before" <(head -c "$size" "$log") && tail -c +$((size + 1)) "$log" > "$work/added" &&
   head -1 "$work/added" | grep -q "^==== sphdisk resume from step 3 (tau 0.018[0-9]*), started .* ====$" &&
   grep -qxF "command: $sphdisk resume $dir -q --set run.max_steps=0" "$work/added" &&
   grep -q "^ranks: 1, threads: 1 per rank" "$work/added" && grep -qxF "code version: $version" "$work/added" &&
   [ "$(count '^step [0-9]' "$work/added")" = 7 ] && [ "$(count '^done: 7 steps' "$work/added")" = 1 ]; then
  ok "resume: appended after a separator naming it, with --quiet's progress and summary"
else
  bad "resume: $(cat "$log")"
fi

# An error ends the log with its message; a SIGKILL leaves every line written so far.
dir=$work/nan
"$sphdisk" run -q "$config" "${small[@]}" --set run.inject_nan_at_step=2 -o "$dir" > /dev/null 2> "$work/err"
if [ $? -eq 3 ] && [ "$(tail -1 "$dir/run.log")" = "$(cat "$work/err")" ]; then
  ok "numerical error: its message ends the log"
else
  bad "numerical error: log ends with '$(tail -1 "$dir/run.log")', stderr '$(cat "$work/err")'"
fi
dir=$work/kill
"$sphdisk" run -q "$config" --set problem.particles=4000 --set 'output.tau=[0.03]' --set output.progress_interval=1e-9 \
  -o "$dir" > /dev/null 2>&1 &
pid=$!
for _ in $(seq 4000); do [ "$(count '^step [0-9]' "$dir/run.log" 2> /dev/null)" -ge 5 ] 2> /dev/null && break; sleep 0.005; done
kill -9 $pid 2> /dev/null
wait $pid 2> /dev/null
rc=$?
if [ $rc -eq 137 ] && grep -qxF "code version: $version" "$dir/run.log" && [ "$(count '^step [0-9]' "$dir/run.log")" -ge 5 ] &&
   [ "$(tail -c 1 "$dir/run.log" | od -An -c | tr -d ' ')" = '\n' ]; then
  ok "SIGKILL: header and $(count '^step [0-9]' "$dir/run.log") whole progress lines kept"
else
  bad "SIGKILL (rc=$rc, 137 if killed mid-run): $(cat "$dir/run.log")"
fi

# --overwrite removes the earlier run's log with its other files.
"$sphdisk" run -q "$config" "${small[@]}" --overwrite -o "$work/run" > /dev/null 2>&1
if [ "$(count '^==== sphdisk' "$work/run/run.log")" = 1 ]; then
  ok "--overwrite: a new log"
else
  bad "--overwrite: $(grep '^====' "$work/run/run.log")"
fi

# Over two ranks, one log: one header and one summary.
if [ -n "$mpiexec" ]; then
  dir=$work/ranks
  "$mpiexec" -np 2 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 "$sphdisk" run -q "$config" "${small[@]}" \
    -o "$dir" > /dev/null 2>&1
  if [ "$(count '^==== sphdisk run' "$dir/run.log")" = 1 ] && grep -q "^ranks: 2, threads: 1 per rank" "$dir/run.log" &&
     [ "$(count '^done: 10 steps' "$dir/run.log")" = 1 ]; then
    ok "2 ranks: one log, written once"
  else
    bad "2 ranks: $(cat "$dir/run.log")"
  fi
fi

finish "run.log: "
