#!/usr/bin/env bash
# Every result says where it came from: `sphdisk --version` prints the code version (the source
# tree's git commit at build time) and the build options, and a snapshot's Header carries the same
# two strings (CodeVersion, BuildOptions). In a git checkout the version names its HEAD commit, so
# a build made before the last commit (a stale version) fails here.
set -euo pipefail
sphdisk=$1
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$sphdisk" --version > "$work/version"
version=$(sed -n '1s/^sphdisk //p' "$work/version")
options=$(sed -n '2s/^build: //p' "$work/version")
echo "version: $version; build: $options"
[ -n "$version" ] && [ -n "$options" ] || { echo "FAIL: --version printed no version or build line"; exit 1; }
if head=$(git -C "$source_dir" rev-parse --short=12 HEAD 2> /dev/null); then
  case "$version" in
    *"git $head"*) echo "names HEAD $head" ;;
    *) echo "FAIL: version '$version' does not name HEAD $head"; exit 1 ;;
  esac
fi
"$sphdisk" run -q -o "$work/run" --set problem.particles=300 --set run.max_steps=1 \
  --set output.progress_interval=0 "$source_dir/tests/validation/small_ring.toml" > /dev/null
/usr/bin/python3 - "$work/run/snapshot_000.hdf5" "$version" "$options" <<'PY'
import sys
import h5py
path, version, options = sys.argv[1:]
with h5py.File(path) as f:
    h = f["Header"].attrs
    got = (h["CodeVersion"].decode(), h["BuildOptions"].decode())
print(f"snapshot Header: CodeVersion '{got[0]}', BuildOptions '{got[1]}'")
sys.exit(0 if got == (version, options) else 1)
PY
