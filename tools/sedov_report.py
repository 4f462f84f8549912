"""The report of a Sedov-Taylor blast-wave run (Header Problem "sedov"): for each output, the
particles' density, radial velocity and pressure against radius beside the similarity solution, and
report.md with `sphdisk analyze`'s L1 norms (docs/physics.md sec. 5). The solution comes from
`sphdisk analyze --json` (its shells' analytic means, 300 shells out to 1.5 shock radii), so that
the report and the analysis share one implementation of it.
"""
import os

import h5py
import numpy as np

from analyze_json import analysis
from report_style import WIDE, corner_note, new_figure, save

SHELLS = 300
FIG = "sedov_{}.png"  # snapshot number of the file name


def is_sedov_run(header):
    return str(header.get("Problem", "")).strip().strip('"') == "sedov"


def particle_profiles(snapshot, gamma):
    """Radius, density, radial velocity and pressure of every particle (positions about the centre)."""
    with h5py.File(snapshot, "r") as f:
        centre = np.asarray(f["Header"].attrs["PointMassPosition"], dtype=float)
        dim = int(f["Header"].attrs.get("SimulationDimension", 3))
        part = f["PartType0"]
        x = part["Coordinates"][:, :dim] - centre[:dim]
        v = part["Velocities"][:, :dim]
        rho = part["Density"][:]
        u = part["InternalEnergy"][:]
    r = np.sqrt((x * x).sum(axis=1))
    vr = np.where(r > 0, (x * v).sum(axis=1) / np.where(r > 0, r, 1), 0.0)
    return r, rho, vr, (gamma - 1) * rho * u


def plot_snapshot(snapshot, a, png):
    r, rho, vr, p = particle_profiles(snapshot, a["gamma"])
    shells = a["bins"]
    centres = np.array([0.5 * (b["r_lo"] + b["r_hi"]) for b in shells])
    fig, axes = new_figure(WIDE, ncols=3)
    for ax, values, key, label in ((axes[0], rho, "rho_ana", r"$\rho$"), (axes[1], vr, "vr_ana", r"$v_r$"),
                                   (axes[2], p, "p_ana", r"$P$")):
        inside = r < centres[-1] + 0.5 * (centres[1] - centres[0])
        ax.plot(r[inside], values[inside], ".", markersize=1, color="0.4", alpha=0.5, rasterized=True, label="particles")
        ax.plot(centres, [b[key] for b in shells], "-", color="C3", label="Sedov-Taylor")
        ax.set_xlabel("$r$")
        ax.set_ylabel(label)
    axes[0].legend(loc="upper left")
    corner_note(axes[2], f"t = {a['time']:.3g}\nN = {a['particles']}", loc="upper left")
    save(fig, png)


def write_report(run, sphdisk, out_dir):
    """Figures and report.md of a blast-wave run; returns the report's path."""
    rows = []
    for snapshot, header in zip(run.snapshots, run.headers):
        if not float(header.get("Time", 0)) > 0:
            continue
        a = analysis(sphdisk, snapshot, SHELLS)
        name = os.path.basename(snapshot)
        png = FIG.format(name.split("_")[-1].split(".")[0])
        plot_snapshot(snapshot, a, os.path.join(out_dir, png))
        budget = a["total_energy"] / a["initial_energy"] - 1
        rows.append((name, a, png, budget))
    md = os.path.join(out_dir, "report.md")
    with open(md, "w") as f:
        f.write(f"# Sedov-Taylor blast wave: {run.run_dir}\n\n")
        if rows:
            a = rows[0][1]
            f.write(f"{a['dimension']}D, N = {a['particles']}, gamma = {a['gamma']:.6g}, E = {a['energy']:.6g}, "
                    f"rho0 = {a['rho0']:.6g}; compared with the similarity solution by `sphdisk analyze` "
                    "(docs/physics.md sec. 5).\n\n")
        f.write("| snapshot | t | shock radius | densest shell r / R | its density | density L1 | v_r L1 | pressure L1 | energy budget |\n")
        f.write("|---|---|---|---|---|---|---|---|---|\n")
        for name, a, _, budget in rows:
            f.write(f"| {name} | {a['time']:.4g} | {a['shock_radius']:.4f} | {a['peak_radius'] / a['shock_radius']:.3f} | "
                    f"{a['peak_density']:.3f} | {a['rho_l1']:.4f} | {a['vr_l1']:.4f} | {a['p_l1']:.4f} | {budget:.2e} |\n")
        f.write("\n")
        for name, a, png, _ in rows:
            f.write(f"![{name}: density, radial velocity and pressure against radius]({png})\n\n")
    return md
