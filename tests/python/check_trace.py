#!/usr/bin/python3
"""`sphdisk run --trace FILE` writes Chrome trace-event JSON (Perfetto) with one track per thread,
and the run directory gets timers.json with every phase.

Usage: check_trace.py SPHDISK CONFIG
"""
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import summarise  # noqa: E402


def main():
    exe, config = sys.argv[1], sys.argv[2]
    checks = []
    with tempfile.TemporaryDirectory() as tmp:
        trace = Path(tmp) / "trace.json"
        env = dict(os.environ, OMP_NUM_THREADS="2")
        subprocess.run([exe, "run", config, "-q", "-o", str(Path(tmp) / "run"), "--trace", str(trace),
                        "--set", "problem.particles=3000", "--set", "output.tau=[0.0183]"],
                       check=True, env=env, stdout=subprocess.DEVNULL)
        events = json.loads(trace.read_text())["traceEvents"]
        checks.append(("trace has complete events", len(events) > 0 and all(e["ph"] == "X" for e in events)))
        checks.append(("one track per thread (2 threads)", len({e["tid"] for e in events}) == 2))
        names = {e["name"] for e in events}
        for phase in ("neighbour_search", "density", "velocity_gradient", "forces", "integration", "io"):
            checks.append((f"phase '{phase}' traced", phase in names))
        checks.append(("durations non-negative", all(e["dur"] >= 0 for e in events)))
        # One "evaluation" event per rate evaluation, with the particles it gave new rates: together
        # the run's evaluations and particle updates (ranks.json), each within the 3000 particles.
        ranks = json.loads((Path(tmp) / "run" / "ranks.json").read_text())[0]
        evaluations = [e for e in events if e["name"] == "evaluation"]
        checks.append((f"{len(evaluations)} evaluation events = rate_evaluations {ranks['rate_evaluations']}",
                       len(evaluations) == ranks["rate_evaluations"]))
        args_ok = all(0 < e["args"]["active"] <= e["args"]["particles"] == 3000 and e["args"]["stage"] in (0, 1)
                      for e in evaluations)
        checks.append(("each evaluation event gives 0 < active <= particles = 3000 and stage 0 or 1", args_ok))
        updates = sum(e["args"]["active"] for e in evaluations)
        checks.append((f"evaluation events' active sum {updates} = particle_updates {ranks['particle_updates']}",
                       updates == ranks["particle_updates"]))
        table = subprocess.run([sys.executable, str(Path(__file__).resolve().parents[2] / "bench" / "evaluation_sizes.py"),
                                str(trace)], check=True, capture_output=True, text=True).stdout
        checks.append(("bench/evaluation_sizes.py tabulates the trace", "<= 100.0%" in table))
        timers = json.loads((Path(tmp) / "run" / "timers.json").read_text())
        for phase in ("cell_build", "neighbour_search", "density", "integration", "io"):
            checks.append((f"timers.json has '{phase}'", phase in timers and timers[phase] >= 0))
        # Pairs searched anew (the default) time the joined gradient and force loops as one phase.
        split = all(p in timers and timers[p] >= 0 for p in ("velocity_gradient", "forces"))
        joined = "gradient_and_forces" in timers and timers["gradient_and_forces"] >= 0
        checks.append(("timers.json has 'velocity_gradient' and 'forces', or 'gradient_and_forces'", split or joined))
    return summarise("trace", checks)


if __name__ == "__main__":
    sys.exit(main())
