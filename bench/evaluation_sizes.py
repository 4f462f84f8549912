#!/usr/bin/python3
"""Where a run's rate evaluations spend their time, by size: reads a trace of `sphdisk run --trace
FILE` (its "evaluation" events carry the particles given new rates, `active`) and prints, for each
class of active share, the evaluations, their wall time and share of the run, the time per
evaluation and per particle update, and the phases inside them (cell build, search, pair loops).
Stages of a super-step (`stage` 1) are counted apart. One process (pid 0), thread 0's track.

Usage: evaluation_sizes.py TRACE.json [--csv OUT.csv]
"""
import argparse
import bisect
import collections
import csv
import json
import sys

EDGES = (0.002, 0.01, 0.1, 0.5, 1.0)  # upper bounds of the active-share classes
PHASES = ("cell_build", "neighbour_search", "search_and_density", "density", "gradient_and_forces",
          "velocity_gradient", "forces")


def outermost(events):
    """Events not inside another event of the same name (a phase timed at two levels counts once)."""
    out, end = [], -1.0
    for e in sorted(events, key=lambda e: (e["ts"], -e["dur"])):
        if e["ts"] >= end:
            out.append(e)
            end = e["ts"] + e["dur"]
    return out


def share_class(active, particles):
    """Index into EDGES of the smallest bound at or above the active share."""
    share = active / particles if particles else 1.0
    return min(bisect.bisect_left(EDGES, share), len(EDGES) - 1)


def tabulate(trace):
    events = [e for e in trace["traceEvents"] if e.get("pid", 0) == 0 and e.get("tid", 0) == 0 and e.get("ph") == "X"]
    evaluations = outermost([e for e in events if e["name"] == "evaluation"])
    starts = [e["ts"] for e in evaluations]
    phases = {name: outermost([e for e in events if e["name"] == name]) for name in PHASES}
    rows = collections.OrderedDict()
    for e in evaluations:
        a = e["args"]
        key = (share_class(a["active"], a["particles"]), "stage" if a["stage"] else "first")
        r = rows.setdefault(key, collections.Counter())
        r["evaluations"] += 1
        r["wall_s"] += e["dur"] * 1e-6
        r["updates"] += a["active"]
    for name, spans in phases.items():  # each phase event into the evaluation that holds it
        for s in spans:
            k = bisect.bisect_right(starts, s["ts"]) - 1
            if k < 0 or s["ts"] + s["dur"] > starts[k] + evaluations[k]["dur"] + 1e-3:
                continue
            a = evaluations[k]["args"]
            rows[(share_class(a["active"], a["particles"]), "stage" if a["stage"] else "first")][name] += s["dur"] * 1e-6
    span = (max(e["ts"] + e["dur"] for e in events) - min(e["ts"] for e in events)) * 1e-6 if events else 0.0
    integration = sum(e["dur"] for e in outermost([e for e in events if e["name"] == "integration"])) * 1e-6
    return rows, span, integration


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trace")
    ap.add_argument("--csv", help="also write the table as CSV")
    args = ap.parse_args()
    with open(args.trace) as f:
        trace = json.load(f)
    rows, span, integration = tabulate(trace)
    if not rows:
        sys.exit("evaluation_sizes.py: no \"evaluation\" events in the trace (a trace of `sphdisk run --trace FILE` "
                 "from a build that records them)")
    total = sum(r["wall_s"] for r in rows.values())
    header = ["active share", "kind", "evaluations", "wall_s", "share_of_run", "ms_per_evaluation",
              "us_per_update", *[f"{p}_s" for p in PHASES]]
    table = []
    for (cls, kind), r in sorted(rows.items()):
        table.append([f"<= {EDGES[cls]:.1%}", kind, r["evaluations"], f"{r['wall_s']:.3f}", f"{r['wall_s'] / span:.3f}" if span else "",
                      f"{1e3 * r['wall_s'] / r['evaluations']:.3f}", f"{1e6 * r['wall_s'] / max(r['updates'], 1):.3f}",
                      *[f"{r[p]:.3f}" for p in PHASES]])
    print(f"trace span {span:.2f} s: evaluations {total:.2f} s ({total / span:.1%}), "
          f"integration {integration:.2f} s ({integration / span:.1%})" if span else "empty trace")
    widths = [max(len(str(x)) for x in col) for col in zip(header, *table)]
    for line in [header, *table]:
        print("  ".join(str(x).rjust(w) for x, w in zip(line, widths)))
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            csv.writer(f).writerows([header, *table])


if __name__ == "__main__":
    main()
