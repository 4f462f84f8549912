#!/usr/bin/env bash
# Speedup and efficiency of one full force evaluation against thread count (P98 Fig. 3) for 10k,
# 100k and 500k particles, and the Fig. 4 comparison with the symmetric sequential variant.
# Writes runs/bench/speedup.csv and runs/bench/speedup.png. Run on an otherwise idle machine.
# Usage: bench/speedup.sh [max_threads]   (default: nproc)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build --preset release --target force_bench > /dev/null
max=${1:-$(nproc)}
threads=$(seq -s, 1 "$max")
out=runs/bench
mkdir -p "$out"
csv=$out/speedup.csv
first=1
for n in 10000 100000 500000; do
  repeats=5
  [ "$n" -ge 500000 ] && repeats=3
  if [ $first -eq 1 ]; then
    build/release/bench/force_bench --particles $n --threads "$threads" --repeats $repeats > "$csv"
    first=0
  else
    build/release/bench/force_bench --particles $n --threads "$threads" --repeats $repeats | tail -n +2 >> "$csv"
  fi
done
/usr/bin/python3 bench/plot_speedup.py "$csv" "$out/speedup.png"
cat "$csv"
