#!/usr/bin/env bash
# Bad input gets a one-line error naming the problem, a non-zero exit, and no damage to existing
# outputs.
set -uo pipefail
sphdisk=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0 failed=0

# expect_error NAME PATTERN -- ARGS...: exit code 2, exactly one line on stderr matching PATTERN.
expect_error() {
  local name=$1 pattern=$2
  shift 3
  "$sphdisk" "$@" > "$work/out" 2> "$work/err"
  local rc=$? lines
  lines=$(wc -l < "$work/err")
  if [ $rc -eq 2 ] && [ "$lines" -eq 1 ] && grep -q -- "$pattern" "$work/err"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL $name: rc=$rc lines=$lines stderr: $(cat "$work/err")"
  fi
}

printf '[problem]\nparticles = -3\n' > "$work/neg.toml"
printf '[problem]\nparticle = 3\n' > "$work/typo.toml"
printf '[problem\nparticles = 3\n' > "$work/broken.toml"
printf '[output]\ntau = [0.09, 0.05]\n' > "$work/order.toml"
printf '[physics]\nviscosity = -1e-8\n' > "$work/visc.toml"
printf '[integrator]\ntolerance = 0\n' > "$work/tol.toml"
printf '[physics]\naccretion_radius = 1.2\n' > "$work/acc.toml"
printf '[problem]\ninitial_conditions = "%s/missing.hdf5"\n' "$work" > "$work/ic.toml"
echo "not hdf5" > "$work/corrupt.hdf5"
printf '[problem]\ninitial_conditions = "%s/corrupt.hdf5"\n' "$work" > "$work/ic2.toml"

expect_error negative "problem.particles must be an integer" -- run "$work/neg.toml" -o "$work/o1"
expect_error typo "did you mean 'problem.particles'" -- run "$work/typo.toml" -o "$work/o1"
expect_error broken-toml "invalid TOML" -- run "$work/broken.toml" -o "$work/o1"
expect_error output-order "output.tau must be strictly increasing" -- run "$work/order.toml" -o "$work/o1"
expect_error viscosity "physics.viscosity must be >= 0" -- run "$work/visc.toml" -o "$work/o1"
expect_error tolerance "integrator.tolerance must be in" -- run "$work/tol.toml" -o "$work/o1"
expect_error accretion "physics.accretion_radius" -- run "$work/acc.toml" -o "$work/o1"
expect_error missing-config "cannot read configuration file" -- run "$work/nope.toml" -o "$work/o1"
expect_error missing-ic "missing.hdf5" -- run "$work/ic.toml" -o "$work/o2"
expect_error corrupt-ic "corrupt.hdf5" -- run "$work/ic2.toml" -o "$work/o3"
expect_error bad-set "expected section.key=value" -- run "$(dirname "$0")/../validation/small_ring.toml" --set problem.particles -o "$work/o1"
expect_error list-skin-retired "sph.list_skin was retired: neighbour lists are built anew" -- run "$(dirname "$0")/../validation/small_ring.toml" --set sph.list_skin=0.2 -o "$work/o1"
expect_error super-steps-scheme "integrator.viscous_update = \"super_steps\" needs integrator.scheme = \"block\"" -- run "$(dirname "$0")/../validation/small_ring.toml" --set 'integrator.viscous_update="super_steps"' --set 'integrator.scheme="leapfrog"' -o "$work/o1"
expect_error super-steps-name "integrator.viscous_update must be one of" -- run "$(dirname "$0")/../validation/small_ring.toml" --set 'integrator.viscous_update="rkl2"' -o "$work/o1"
expect_error gradient-correction-name "sph.gradient_correction must be one of" -- run "$(dirname "$0")/../validation/small_ring.toml" --set 'sph.gradient_correction="shepard"' -o "$work/o1"
expect_error pair-lists-name "sph.pair_lists must be one of" -- run "$(dirname "$0")/../validation/small_ring.toml" --set 'sph.pair_lists="none"' -o "$work/o1"
expect_error missing-snapshot "cannot open" -- analyze "$work/none.hdf5"
printf 'base = "%s"\noutput = "%s/sw"\n[[run]]\nname = ".."\nset = []\n' "$(cd "$(dirname "$0")/../validation" && pwd)/small_ring.toml" "$work" > "$work/dots.toml"
printf 'base = "%s"\noutput = "%s/sw"\n[[run]]\nname = "a"\nset = "problem.particles=2000"\n' "$(cd "$(dirname "$0")/../validation" && pwd)/small_ring.toml" "$work" > "$work/setstring.toml"
expect_error sweep-set-not-a-list "'set' must be a list of \"section.key=value\" strings (in brackets, even for one)" -- sweep "$work/setstring.toml"
expect_error sweep-dots-name "run name '..' must use only letters, digits, _ . - and not be dots alone" -- sweep "$work/dots.toml"
expect_error threads-not-a-number "threads: 'abc' is not a whole number" -- run "$(dirname "$0")/../validation/small_ring.toml" -t abc -o "$work/o1"
expect_error negative-threads "threads: -1 is not in \[0, 4096\]" -- run "$(dirname "$0")/../validation/small_ring.toml" -t -1 -o "$work/o1"
expect_error unwritable "not writable\|cannot create output directory" -- run "$(dirname "$0")/../validation/small_ring.toml" -o /proc/sphdisk

ring="$(dirname "$0")/../validation/small_ring.toml"
expect_error config-is-directory "is a directory, not a configuration file" -- run "$work" --check
expect_error empty-output "was given an empty directory name" -- run "$ring" -o ''
expect_error trace-directory-missing "the directory '$work/nowhere' does not exist" -- run "$ring" -o "$work/o1" --trace "$work/nowhere/t.json"
expect_error too-few-particles "problem.particles = 10 is too few for 60 neighbours" -- run "$ring" --set problem.particles=10 -o "$work/o1"
expect_error check-missing-ic "problem.initial_conditions: no file" -- run "$ring" --set "problem.initial_conditions=\"$work/none.hdf5\"" --check
expect_error too-few-particles-check "problem.particles = 10 is too few" -- run "$ring" --set problem.particles=10 --check
# The user's own config.toml in the output directory (say the file being run) is never replaced,
# with or without --overwrite.
mkdir -p "$work/own" && cp "$ring" "$work/own/config.toml"
for flag in "" --overwrite; do
  expect_error "own-config-toml$flag" "holds a config.toml that no run wrote" -- run "$work/own/config.toml" $flag -o "$work/own"
done
if cmp -s "$ring" "$work/own/config.toml" && [ "$(ls "$work/own")" = config.toml ]; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL: the user's config.toml was changed or files were added: $(ls "$work/own")"
fi

# A particle count that cannot fit in memory is refused up front with the estimate.
expect_error memory "particles need about .* GiB but this machine has" -- run "$(dirname "$0")/../validation/small_ring.toml" --set problem.particles=2000000000 -o "$work/o5"

# A full disk (simulated by a file-size limit, with SIGXFSZ ignored so writes fail with EFBIG): one
# line naming the file and the fix, and no partial snapshot left behind.
full_disk() { (trap '' XFSZ; ulimit -f 100; exec "$sphdisk" "$@"); }
full_disk run -q "$(dirname "$0")/../validation/small_ring.toml" -o "$work/full" > /dev/null 2> "$work/err"
rc=$?
if [ $rc -eq 2 ] && [ "$(wc -l < "$work/err")" -eq 1 ] && grep -q "cannot write .*snapshot_000.hdf5.*free disk space" "$work/err" &&
   [ -z "$(find "$work/full" -name '*.hdf5*')" ]; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL full-disk: rc=$rc $(cat "$work/err"); files: $(ls "$work/full")"
fi

# Inputs that once crashed the parsers (found by fuzzing, fuzz/) now get a clean one-line error.
regressions="$(dirname "$0")/../fuzz_regressions"
for f in "$regressions"/*.toml; do
  expect_error "fuzz-$(basename "$f")" "$(basename "$f")" -- run "$f" --check -o "$work/o1"
done
for f in "$regressions"/*.hdf5; do
  expect_error "fuzz-$(basename "$f")" "$(basename "$f")" -- analyze "$f"
  rm -rf "$work/r" && mkdir "$work/r" && cp "$f" "$work/r/checkpoint.hdf5"
  expect_error "fuzz-resume-$(basename "$f")" "checkpoint.hdf5" -- resume "$work/r"
  expect_error "fuzz-ic-$(basename "$f")" "$(basename "$f")" -- run "$(dirname "$0")/../validation/small_ring.toml" --set "problem.initial_conditions=\"$f\"" -o "$work/o4"
done

# Command-line mistakes: exit 2, one line, and the closest command or option.
expect_error mistyped-subcommand "did you mean 'run'" -- rnu "$(dirname "$0")/../validation/small_ring.toml"
expect_error mistyped-option "did you mean '--overwrite'" -- run "$(dirname "$0")/../validation/small_ring.toml" --overwrit
expect_error unknown-option "not expected" -- analyze "$work/none.hdf5" --frobnicate
expect_error unknown-command "unknown command 'frobnicate'; the commands are run resume" -- frobnicate

# Existing outputs are never overwritten without --overwrite.
small=(--set problem.particles=500 --set 'output.tau=[0.0182]' --set output.progress_interval=0)
"$sphdisk" run -q "${small[@]}" -o "$work/run" "$(dirname "$0")/../validation/small_ring.toml" > /dev/null 2>&1
before=$(md5sum "$work/run/snapshot_001.hdf5")
expect_error overwrite "already holds results" -- run "${small[@]}" -o "$work/run" "$(dirname "$0")/../validation/small_ring.toml"
after=$(md5sum "$work/run/snapshot_001.hdf5")
if [ "$before" = "$after" ]; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: existing snapshot changed"; fi

# A run directory of a version that wrote no run.log (config.toml beside its snapshots) is still an
# earlier run: --overwrite replaces it.
cp -r "$work/run" "$work/oldrun" && rm -f "$work/oldrun/run.log"
if "$sphdisk" run -q "${small[@]}" --overwrite -o "$work/oldrun" "$(dirname "$0")/../validation/small_ring.toml" > /dev/null 2>&1 &&
   [ -f "$work/oldrun/run.log" ]; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL: --overwrite refused an earlier run's directory without run.log"
fi
# A study's runs get the run's own checks before any starts.
printf 'base = "%s"\noutput = "%s/sw2"\n[[run]]\nname = "a"\nset = ["problem.particles=10"]\n' "$(cd "$(dirname "$0")/../validation" && pwd)/small_ring.toml" "$work" > "$work/fewstudy.toml"
expect_error sweep-too-few-particles "run 'a': problem.particles = 10 is too few" -- sweep "$work/fewstudy.toml"

# A checkpoint given to analyze, a snapshot in the place of a run's checkpoint.
expect_error analyze-checkpoint "is an sphdisk checkpoint, not a snapshot; give a snapshot_NNN.hdf5" -- analyze "$work/run/checkpoint.hdf5"
mkdir -p "$work/snaprun" && cp "$work/run/snapshot_001.hdf5" "$work/snaprun/checkpoint.hdf5"
expect_error resume-snapshot "not an sphdisk checkpoint" -- resume "$work/snaprun"

# A 2D run's snapshot as the initial conditions of a 3D run.
expect_error ic-dimension "holds a 2D run (Header/SimulationDimension) but sph.dimension = 3" -- run "$ring" -o "$work/o7" \
  --set sph.dimension=3 --set 'physics.eos="isothermal"' --set physics.aspect_ratio=0.05 --set "problem.initial_conditions=\"$work/run/snapshot_001.hdf5\""

# Truncated snapshot and checkpoint (a copy cut in half, as after an interrupted transfer).
cp "$work/run/snapshot_001.hdf5" "$work/cut.hdf5"
truncate -s $(( $(stat -c %s "$work/cut.hdf5") / 2 )) "$work/cut.hdf5"
expect_error truncated-snapshot "cut.hdf5" -- analyze "$work/cut.hdf5"
expect_error truncated-ic "cut.hdf5" -- run "$(dirname "$0")/../validation/small_ring.toml" --set "problem.initial_conditions=\"$work/cut.hdf5\"" -o "$work/o6"
mkdir -p "$work/cutrun" && cp "$work/run/checkpoint.hdf5" "$work/cutrun/checkpoint.hdf5"
truncate -s $(( $(stat -c %s "$work/cutrun/checkpoint.hdf5") / 2 )) "$work/cutrun/checkpoint.hdf5"
expect_error truncated-checkpoint "checkpoint.hdf5" -- resume "$work/cutrun"

# --overwrite removes what the earlier run wrote, so two runs' outputs never mix: a run with two
# outputs replaced by one with one leaves no snapshot_002, no report of the old run, and files of
# other names untouched.
"$sphdisk" run -q "${small[@]}" --set 'output.tau=[0.0182, 0.0184]' -o "$work/mix" "$(dirname "$0")/../validation/small_ring.toml" > /dev/null 2>&1
mkdir -p "$work/mix/report" && echo "mine" > "$work/mix/notes.txt"
"$sphdisk" run -q "${small[@]}" --overwrite -o "$work/mix" "$(dirname "$0")/../validation/small_ring.toml" > /dev/null 2>&1
if [ -f "$work/mix/snapshot_001.hdf5" ] && [ ! -e "$work/mix/snapshot_002.hdf5" ] && [ ! -e "$work/mix/report" ] &&
   [ "$(cat "$work/mix/notes.txt")" = "mine" ]; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL: --overwrite left the earlier run's outputs or removed another file: $(ls "$work/mix")"
fi

# A run stopped by run.max_steps leaves a checkpoint that `resume` continues.
"$sphdisk" run -q "${small[@]}" --set 'integrator.scheme="leapfrog"' --set run.max_steps=2 -o "$work/short" "$(dirname "$0")/../validation/small_ring.toml" > /dev/null 2>&1
if [ -f "$work/short/checkpoint.hdf5" ] && "$sphdisk" resume -q "$work/short" > /dev/null 2>&1; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL: a run stopped by run.max_steps left no checkpoint to resume"
fi

# A checkpoint written before sph.viscous_force existed continues with the conservative form it ran
# (the fixture of format 2): the same diagnostics as when it is named.
fixture="$(dirname "$0")/../fixtures/checkpoint_format2.hdf5"
for v in implicit conservative; do
  mkdir -p "$work/old_$v" && cp "$fixture" "$work/old_$v/checkpoint.hdf5"
  extra=(); [ $v = conservative ] && extra=(--set 'sph.viscous_force="conservative"')
  "$sphdisk" resume -q "$work/old_$v" --set run.max_steps=2 "${extra[@]}" > /dev/null 2>&1
done
if [ -s "$work/old_implicit/diagnostics.csv" ] &&
   [ "$(cut -d, -f1-10 "$work/old_implicit/diagnostics.csv")" = "$(cut -d, -f1-10 "$work/old_conservative/diagnostics.csv")" ]; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL: an old checkpoint did not continue with the conservative viscous force"
fi

echo "cli errors: $passed passed, $failed failed"
[ $failed -eq 0 ]
