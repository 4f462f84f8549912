#!/usr/bin/env bash
# problem.initial_conditions: a relative path in a configuration file is taken from that file's
# directory, whatever the current one; with --set, from the current directory; an absolute path as
# given. The resolved path goes into config.toml, and a missing file's error names it.
set -uo pipefail
sphdisk=$(realpath "$1")
config=$(realpath "$(dirname "$0")/../validation/small_ring.toml")
. "$(dirname "$0")/../lib/checks.sh"  # $work, ok, bad, finish
small=(--set problem.particles=500 --set 'output.tau=[0.0182]' --set output.progress_interval=0)

# Initial conditions: the first snapshot of a short ring run, in a set-up directory beside its
# configuration; the runs start from another directory.
"$sphdisk" run -q "$config" "${small[@]}" --set run.max_steps=1 -o "$work/make" > /dev/null 2>&1 || { echo "set-up run failed"; exit 1; }
mkdir -p "$work/setup/ics" "$work/elsewhere"
cp "$work/make/snapshot_000.hdf5" "$work/setup/ics/ring.hdf5"
printf 'problem.initial_conditions = "ics/ring.hdf5"\n' > "$work/setup/relative.toml"
printf 'problem.initial_conditions = "%s/setup/ics/ring.hdf5"\n' "$work" > "$work/setup/absolute.toml"
printf 'problem.initial_conditions = "ics/none.hdf5"\n' > "$work/setup/missing.toml"
cd "$work/elsewhere" || exit 1

if "$sphdisk" run -q ../setup/relative.toml "${small[@]}" -o out_rel > "$work/err" 2>&1 &&
   grep -qx "initial_conditions = \"$work/setup/ics/ring.hdf5\"" out_rel/config.toml; then
  ok "relative path in a configuration file: from its directory, stored resolved in config.toml"
else
  bad "relative path in a configuration file: $(cat "$work/err")"
fi
if "$sphdisk" run -q "$work/setup/absolute.toml" "${small[@]}" -o out_abs > "$work/err" 2>&1 &&
   h5diff -q out_rel/snapshot_001.hdf5 out_abs/snapshot_001.hdf5 /PartType0 /PartType0; then
  ok "absolute path: the same file, the same result"
else
  bad "absolute path: $(cat "$work/err")"
fi
if (cd "$work/setup" && "$sphdisk" run -q "$config" "${small[@]}" --set 'problem.initial_conditions="ics/ring.hdf5"' \
      -o "$work/elsewhere/out_set") > "$work/err" 2>&1 &&
   h5diff -q out_rel/snapshot_001.hdf5 out_set/snapshot_001.hdf5 /PartType0 /PartType0; then
  ok "relative path with --set: from the current directory"
else
  bad "relative path with --set: $(cat "$work/err")"
fi

# Missing files: exit 2, one line naming the path as resolved.
expect_missing() {
  local name=$1 path=$2
  shift 2
  "$sphdisk" "$@" > /dev/null 2> "$work/err"
  local rc=$?
  if [ $rc -eq 2 ] && [ "$(wc -l < "$work/err")" -eq 1 ] && grep -qF "'$path'" "$work/err"; then
    ok "$name: $(cat "$work/err")"
  else
    bad "$name: rc=$rc $(cat "$work/err")"
  fi
}
expect_missing "missing file of a configuration" "$work/setup/ics/none.hdf5" run -q ../setup/missing.toml "${small[@]}" -o out_m1
expect_missing "missing file of --set" "$work/elsewhere/none.hdf5" run -q "$config" "${small[@]}" \
  --set 'problem.initial_conditions="none.hdf5"' -o out_m2

finish "initial conditions path: "
