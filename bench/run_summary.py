#!/usr/bin/python3
"""One CSV row describing a finished run (for the benchmark scripts that compare variants of it).

Usage: run_summary.py --header NAME...         the header: date, the NAMEs, then the measured columns
       run_summary.py DIR START END VALUE...   the row of run directory DIR (START, END: wall-clock
                                               seconds around the run; VALUEs: the variant's NAMEs)
Measured columns: wall time, rate evaluations, evaluations that built their lists, particle updates,
peak RSS per particle of rank 0 (its particles at the end), and the phase times (search with the h solve and cell build, list
check, density, velocity gradient, forces, and the two loops joined where the pairs are searched anew,
gradient_and_forces) from ranks.json.
"""
import datetime
import json
import sys

MEASURED = ("wall_s,evaluations,list_builds,particle_updates,peak_rss_bytes_per_particle,"
            "search_s,density_s,velocity_gradient_s,forces_s,gradient_and_forces_s,search_and_density_s")

if sys.argv[1] == "--header":
    print(",".join(["date", *sys.argv[2:], MEASURED]))
    sys.exit(0)
d, start, end, *values = sys.argv[1:]
r = json.load(open(f"{d}/ranks.json"))[0]
t = r["timers"]
cols = [
    f"{float(end) - float(start):.2f}", str(r["rate_evaluations"]), str(r["list_builds"]), str(r["particle_updates"]),
    f"{r['peak_rss_bytes'] / r['particles']:.0f}",
    f"{t.get('cell_build', 0) + t.get('neighbour_search', 0):.2f}",
    f"{t['density']:.2f}", f"{t.get('velocity_gradient', 0):.2f}", f"{t.get('forces', 0):.2f}",
    f"{t.get('gradient_and_forces', 0):.2f}", f"{t.get('search_and_density', 0):.2f}",
]
print(",".join([str(datetime.date.today()), *values, *cols]))
