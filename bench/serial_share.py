#!/usr/bin/env python3
"""How much of a run the main thread spends outside parallel regions (Amdahl's serial share).

Reads `perf script -F tid,ip,sym` output of a `perf record -e cpu-clock --call-graph dwarf` run
(a build with -g gives names to inlined frames) and counts, for the thread with the most samples
(the main thread), the samples whose call chain holds no OpenMP parallel region. Prints that share
and the serial samples grouped by their innermost sphdisk frames.

  perf record -e cpu-clock --call-graph dwarf,16384 -o perf.data build/sphdisk run ... -t 2
  perf script -i perf.data -F tid,ip,sym > chains.txt
  bench/serial_share.py chains.txt [ROWS]
"""
import collections
import sys


def samples(path):
    current = None
    with open(path, errors="replace") as f:
        for line in f:
            if not line.strip():
                if current:
                    yield current
                current = None
            elif not line[0].isspace():
                current = (line.split()[0], [])
            elif current is not None:
                parts = line.strip().split(None, 1)
                current[1].append(parts[1] if len(parts) > 1 else "?")
    if current:
        yield current


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: serial_share.py CHAINS [ROWS]  (perf script -F tid,ip,sym output)")
    rows = int(sys.argv[2]) if len(sys.argv) > 2 else 25
    all_samples = list(samples(sys.argv[1]))
    if not all_samples:
        sys.exit(f"serial_share.py: no samples in {sys.argv[1]}; record with --call-graph and pass `perf script -F tid,ip,sym` output")
    per_thread = collections.Counter(tid for tid, _ in all_samples)
    main_tid = per_thread.most_common(1)[0][0]
    in_main = serial = 0
    where = collections.Counter()
    for tid, frames in all_samples:
        if tid != main_tid:
            continue
        in_main += 1
        if any("GOMP_parallel" in f or "._omp_fn" in f for f in frames):
            continue
        serial += 1
        chain = [f.split("(")[0][:60] for f in frames if f.startswith("sphdisk::")]
        where[" < ".join(chain[:3]) or frames[0][:60]] += 1
    print(f"threads: {len(per_thread)}; main thread samples: {in_main}; outside parallel regions: "
          f"{serial} ({100.0 * serial / in_main:.1f}%)")
    for chain, count in where.most_common(rows):
        print(f"{100.0 * count / in_main:6.2f}%  {chain}")


if __name__ == "__main__":
    main()
