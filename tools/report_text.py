"""The Markdown of the run report: summary (what ran, the ring's verdict figures, conservation),
figures, then the details (run, parameters, accuracy or disc table, diagnostics, notes).
"""
import math
import os
import re

import numpy as np

from disc_profiles import PROFILES_CSV
from ring_model import BIN_RANGE, FLOOR_FACTOR, N_BINS, NOISE_SDS, RATE_TOLERANCE, SCATTER_CUT, verdict
from run_data import largest_change

SOLAR_UNITS = [("UnitLength_in_cm", "length", 6.957e10, "R☉"), ("UnitMass_in_g", "mass", 1.98841e33, "M☉")]


def run_wall_time(wall):
    """Wall seconds of the steps kept in diagnostics.csv and the number of processes that ran them:
    the column counts from each start or resume, so it drops where a resume begins, and the total
    is the sum of each part's last value."""
    wall = [float(w) for w in wall]
    ends = [a for a, b in zip(wall, wall[1:]) if b < a] + wall[-1:]
    return sum(ends), len(ends)


def fmt(value):
    """Compact text for a table cell; "–" for a missing or non-finite number."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(fmt(v) for v in value) + "]"
    return str(value).replace("|", "\\|").replace("\n", " ")


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(fmt(c) for c in row) + " |" for row in rows]
    return lines


def workers_text(run):
    """Threads and ranks as far as the run directory records them: run.log's line of each process that
    ran it (the run and its resumes, on any counts), else ranks.json and run.threads."""
    segments = logged_workers(os.path.join(run.run_dir, "run.log"))
    if segments:
        text = ", then ".join(f"{r} MPI rank{'s' if r > 1 else ''} x {t} thread{'s' if t > 1 else ''}" for r, t in segments)
        return text + (" (run.log: the run and its resumes)" if len(segments) > 1 else " (run.log)")
    parts = []
    threads = run.params.get("run.threads")
    recorded = (run.ranks or [{}])[0].get("threads") if run.ranks else None
    if recorded:
        parts.append(f"{recorded} threads")
    elif isinstance(threads, (int, float)) and threads > 0:
        parts.append(f"{int(threads)} threads (run.threads)")
    else:
        parts.append("threads not recorded (run.threads = 0: OMP_NUM_THREADS or all cores)")
    if run.ranks:
        parts.append(f"{len(run.ranks)} MPI rank{'s' if len(run.ranks) > 1 else ''} (ranks.json)")
    return ", ".join(parts)


def logged_workers(path):
    """(ranks, threads per rank) of each process run.log records, in order; [] without run.log."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            found = [re.match(r"ranks: (\d+), threads: (\d+) per rank", line) for line in f]
    except OSError:
        return []
    return [(int(m.group(1)), int(m.group(2))) for m in found if m]


def span_text(run, all_stats):
    """First to last snapshot in time, orbits at r0 (period 2 pi), viscous time, steps and wall time."""
    first, last = all_stats[0], all_stats[-1]
    orbits = (last.time - first.time) / (2 * math.pi)
    text = f"t = {first.time:.4g} to {last.time:.4g} code units ({orbits:.3g} orbits at r0)"
    if run.ring_run and first.tau is not None and last.tau is not None:
        text += f", τ = {first.tau:.4g} to {last.tau:.4g}"
    if run.diag is not None:
        text += f"; {fmt(run.diag['step'][-1])} steps, wall time {run_wall_time(run.diag['wall_time'])[0]:.4g} s"
    return text + f"; {len(all_stats)} snapshots"


def problem_text(run):
    """Which problem ran, and what says so (docs/formats.md; ring_model.is_ring_run)."""
    header = run.headers[0]
    if "Problem" in header:
        return f"`{header['Problem']}` (Header Problem)"
    if run.ring_run:
        return "`ring` (generated set-up; no Header Problem)"
    return f"disc from `{run.params.get('problem.initial_conditions')}` (no Header Problem)"


def rate_noise_text(stats, rate_sd):
    """The rate's departure in standard deviations of its sampling scatter (`sphdisk analyze`'s
    rate_sampling_sd, the spread of tau*/tau over random draws of N particles from the analytic ring):
    within NOISE_SDS sd N particles cannot tell it from noise. Empty without a scatter."""
    if not rate_sd:
        return ""
    sds = abs(stats.rate - 1.0) / rate_sd
    return (f" (τ*/τ - 1 = {stats.rate - 1.0:+.4f} = {sds:.1f} sd of its sampling scatter {rate_sd:.4f}: "
            f"{'within' if sds <= NOISE_SDS else 'beyond'} the noise of {stats.particles} particles)")


def ring_verdict_lines(stats, rate_sd=None):
    """The ring's verdict figures (docs/physics.md sec. 4) of one snapshot; rate_sd: its rate's
    sampling scatter from `sphdisk analyze`, where known."""
    if stats.rate is None or stats.l1_mass is None:
        return []
    rate_ok, noise_ok = (("yes" if ok else "no") for ok in verdict(stats.rate, stats.l1_mass, stats.floor))
    ratio = f" = {stats.l1_mass / stats.floor:.2f} × its sampling floor {stats.floor:.4f}" if stats.floor else ""
    return [f"- Spreading rate at τ = {stats.tau:.4g} ({stats.name}): τ*/τ = {stats.rate:.4f} "
            f"(annulus-mass L1 {stats.l1_at_fit:.4f} at τ*); within {RATE_TOLERANCE:.0%}: {rate_ok}"
            f"{rate_noise_text(stats, rate_sd)}.",
            f"- Annulus-mass L1 {stats.l1_mass:.4f}{ratio}; within {FLOOR_FACTOR}× the floor: {noise_ok}."]


def conservation_lines(run):
    """Largest relative drift of mass and angular momentum (each plus the accreted part) over the run."""
    if run.diag is None:
        return ["- Conservation: diagnostics.csv missing or unusable."]
    d = run.diag
    dm = largest_change(d["mass"] + d["accreted_mass"])
    dl = largest_change(d["angular_momentum"] + d["accreted_angular_momentum"])
    m0 = (d["mass"] + d["accreted_mass"])[0]
    accreted = d["accreted_mass"][-1] / m0 if m0 else math.nan
    return [f"- Conservation (diagnostics.csv, largest relative change over {len(d['step'])} rows): "
            f"mass + accreted mass {fmt(dm)}, L_z + accreted L_z {fmt(dl)}; accreted by the end: "
            f"{fmt(accreted)} of the initial mass."]


def section_summary(run, all_stats, rate_sd=None):
    """What ran, over which time, the ring's verdict figures (ring runs) and conservation."""
    n0, n1 = all_stats[0].particles, all_stats[-1].particles
    kernel = str(run.params.get("sph.kernel", "cubic")).strip('"')
    lines = ["## Summary", "",
             f"- Problem: {problem_text(run)}; N = {n0}" + (f" ({n1} at the end)" if n1 != n0 else "")
             + f"; integrator `{run.params.get('integrator.scheme', 'not recorded')}`, kernel `{kernel}`; "
             + workers_text(run) + ".",
             f"- Time span: {span_text(run, all_stats)}."]
    if run.ring_run:
        lines += ring_verdict_lines(all_stats[-1], rate_sd)
    else:
        lines.append("- Not a ring run: radial profiles of the disc as it is, no comparison with the ring solution.")
    return lines + conservation_lines(run) + [""]


def section_figures(figures):
    lines = ["## Figures", "", "Each figure is also in vector form: the same name with `.pdf`.", ""]
    for caption, name in figures:
        lines += [f"### {caption}", "", f"![{caption}]({name})", ""]
    return lines


def units_text(units):
    """The code units in solar values where /Units gives them."""
    units = units or {}
    parts = [f"{what} {float(units[key]) / solar:.6g} {name}"
             for key, what, solar, name in SOLAR_UNITS if units.get(key)]
    if units.get("UnitTime_in_s"):
        parts.append(f"time {float(units['UnitTime_in_s']):.6g} s")
    return ", ".join(parts) if parts else "not recorded (no /Units)"


def first_present(header, *names):
    return next((k for k in names if k in header), names[0])


def section_run(run):
    header0 = run.headers[0]
    # CodeName and SimulationDimension, where a file has them (the layout yt's SWIFT reader takes), name
    # the code and the run's dimension; older files say the same with Code and Dimension.
    keys = [first_present(header0, "CodeName", "Code"), first_present(header0, "SimulationDimension", "Dimension"),
            "Problem", "DiskMass", "RingRadius", "KinematicViscosity", "ViscousTime", "Time"]
    rows = [(k, header0[k]) for k in keys if k in header0]
    return (["### Run", "", f"Run directory: `{os.path.abspath(run.run_dir)}`, {len(run.snapshots)} snapshots. "
             f"Code units G = M = 1 with r0 the length unit: {units_text(run.units)}.", "",
             "Initial state (`/Header` of the first snapshot):", ""]
            + table(["attribute", "value"], rows) + [""])


def section_parameters(params):
    lines = ["### Parameters", ""]
    if not params:
        return lines + ["The first snapshot has no `/Parameters` attributes.", ""]
    return lines + table(["parameter", "value"], sorted(params.items())) + [""]


def section_accuracy(all_stats):
    lines = ["### Accuracy against the analytic ring solution", "",
             f"{N_BINS} bins in [{BIN_RANGE[0]}, {BIN_RANGE[1]}] r0. L1 binned particle Σ: against the mean of "
             "Σ_ana at the particles' radii (empty bins skipped). L1 annulus mass/area: against the analytic "
             "annulus mean, with its sampling floor and the best-fit viscous time τ* (docs/physics.md sec. 4). "
             f"Scatter: std of Σ_sph/Σ_ana - 1 over particles with Σ_ana > {SCATTER_CUT:.0%} of its peak.", ""]
    rows = [(s.name, s.time, s.tau, s.particles, s.l1, s.l1_mass, s.scatter, s.floor, s.rate) for s in all_stats]
    return lines + table(["snapshot", "time", "τ", "particles", "L1 binned particle Σ", "L1 annulus mass/area",
                          "particle scatter", "sampling floor", "τ*/τ"], rows) + [""]


def median_finite(values):
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else None


def section_disc(all_stats, profiles):
    """Per snapshot of a disc other than the ring: mass, accreted mass and typical mass flux."""
    lines = ["### Disc by snapshot", "",
             f"Radial profiles of every snapshot in `{PROFILES_CSV}` (empty cells: empty bins). "
             "Ṁ = -2π r Σ ⟨v_r⟩ is positive inward; the column gives its median over the bins.", ""]
    rows = [(s.name, s.time, s.particles, s.mass, s.accreted, median_finite(p.mdot(p.vr)),
             median_finite(p.mdot(p.vr_drift))) for s, p in zip(all_stats, profiles)]
    return lines + table(["snapshot", "time", "particles", "disc mass", "accreted mass", "Ṁ (particle v_r)",
                          "Ṁ (drift)"], rows) + [""]


def section_diagnostics(run):
    lines = ["### Run diagnostics", ""]
    if run.diag is None:
        lines += ["diagnostics.csv missing, empty or lacking columns: conservation figure and wall time skipped.", ""]
    else:
        last = {c: run.diag[c][-1] for c in ("step", "tau", "time", "wall_time")}
        when = f"τ = {last['tau']:.6g}" if run.ring_run else f"t = {last['time']:.6g}"
        total, parts = run_wall_time(run.diag["wall_time"])
        over = f", the sum over the run and its {parts - 1} resume(s)" if parts > 1 else ""
        lines += [f"Wall time: {total:.6g} s (diagnostics.csv to its last row: step {fmt(last['step'])}, "
                  f"{when}{over}).", ""]
    if run.timers:
        lines += ["Timers (timers.json):", ""] + table(["phase", "seconds"], list(run.timers.items())) + [""]
    return lines


def write_markdown(path, run, all_stats, profiles, rate_sd=None):
    """report.md; rate_sd: the last snapshot's rate sampling scatter (`sphdisk analyze`), where known."""
    lines = [f"# sphdisk run report: {os.path.basename(os.path.abspath(run.run_dir))}", ""]
    lines += section_summary(run, all_stats, rate_sd)
    lines += section_figures(run.figures)
    lines += ["## Details", ""] + section_run(run) + section_parameters(run.params)
    lines += section_accuracy(all_stats) if run.ring_run else section_disc(all_stats, profiles)
    lines += section_diagnostics(run)
    if run.notes:
        lines += ["### Notes", ""] + [f"- {n}" for n in run.notes] + [""]
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines))

