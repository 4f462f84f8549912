#!/usr/bin/env bash
# CPU seconds per rank and step of ring runs on 1 and 2 ranks, for bench/scaling_model.py's cost per
# pair interaction: runs of 2 and 12 steps, each rank under /usr/bin/time; the difference / 10 is
# one step without the set-up. CPU time (unlike wall time) holds on a machine shared with other
# work, except that a waiting rank's polling counts too.
# Usage: bench/scaling_cpu_times.sh > OUT.csv [N ...]   (default N: 100000 500000; two repeats)
set -euo pipefail
cd "$(dirname "$0")/.."
sizes=("$@")
[ $# -gt 0 ] || sizes=(100000 500000)
echo "particles,ranks,steps,repeat,rank,user_s,sys_s"
for n in "${sizes[@]}"; do for rep in 1 2; do for r in 1 2; do for s in 2 12; do
  dir=runs/scale/cpu_N${n}_P${r}_S${s}
  mpirun -np "$r" --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 -x OMPI_MCA_mpi_yield_when_idle=1 \
    bash -c '/usr/bin/time -f "%U %S" -o '"$dir"'.time.$OMPI_COMM_WORLD_RANK build/release/sphdisk run \
      configs/ring.toml -q --overwrite -o '"$dir"' --set problem.particles='"$n"' --set run.max_steps='"$s"' \
      --set checkpoint.every_seconds=0 --set "output.tau=[0.126]" --set integrator.scheme=leapfrog \
      --set sph.pair_lists=stored' > /dev/null
  for k in $(seq 0 $((r - 1))); do
    read -r user sys < "$dir.time.$k"
    echo "$n,$r,$s,$rep,$k,$user,$sys"
  done
  rm -rf "$dir" "$dir".time.*
done; done; done; done
