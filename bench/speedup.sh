#!/usr/bin/env bash
# Speedup and efficiency of one full force evaluation against thread count (P98 Fig. 3) for 10k,
# 100k and 500k particles, and the Fig. 4 comparison with the symmetric sequential variant.
# Writes runs/bench/speedup.csv and runs/bench/speedup.png. Run on an otherwise idle machine.
# Usage: bench/speedup.sh [max_threads] [runs]   (default: nproc, 1)
# With runs > 1 every particle number is measured that many times, the runs of all sizes
# interleaved (a VM's slow spells then hit every size alike); the plot and
# runs/bench/speedup_median.csv use the median time of each (variant, threads, N), with the range of
# the 2-thread efficiency and of the parallel/symmetric ratio over the runs.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build --preset release --target force_bench > /dev/null
max=${1:-$(nproc)}
runs=${2:-1}
threads=$(seq -s, 1 "$max")
out=runs/bench
mkdir -p "$out"
csv=$out/speedup.csv
echo "run,variant,threads,particles,neighbours,seconds_per_evaluation,particle_updates_per_second,pair_interactions_per_second,best_seconds_per_evaluation" > "$csv"
for run in $(seq 1 "$runs"); do
  for n in 10000 100000 500000; do
    repeats=11
    [ "$n" -ge 500000 ] && repeats=5
    build/release/bench/force_bench --particles $n --threads "$threads" --repeats $repeats \
      | tail -n +2 | grep -v "^symmetric vs" | sed "s/^/$run,/" >> "$csv"
  done
done
/usr/bin/python3 bench/plot_speedup.py "$csv" "$out/speedup.png" "$out/speedup_median.csv"
cat "$out/speedup_median.csv"
