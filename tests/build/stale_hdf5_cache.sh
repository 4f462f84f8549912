#!/usr/bin/env bash
# A build directory configured before HDF5's parallel flavour was installed holds FindHDF5's cached
# "not parallel"; configuring it again, with the library now there, must succeed (CMakeLists.txt
# learns the flavour anew) rather than call the parallel library the serial one (a configuration with
# SPHDISK_MPI on, the default, stops on a serial flavour).
# Usage: stale_hdf5_cache.sh SOURCE_DIR SCRATCH_DIR
set -euo pipefail
src=$1 dir=$2
rm -rf "$dir"
mkdir -p "$(dirname "$dir")"
if ! cmake -S "$src" -B "$dir" -DHDF5_IS_PARALLEL=FALSE -DSPHDISK_TESTS=OFF > "$dir.log" 2>&1; then
  tail -5 "$dir.log"
  echo "FAIL: a stale cached HDF5_IS_PARALLEL=FALSE stopped the configuration"
  exit 1
fi
echo "ok: configured over a stale HDF5 flavour"
rm -rf "$dir" "$dir.log"
