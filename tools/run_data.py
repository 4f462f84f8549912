"""Reading a sphdisk run directory (docs/formats.md): snapshots, their attributes and particles,
diagnostics.csv, timers.json and ranks.json; and the conserved sums of diagnostics.csv.
"""
import csv
import json
import math
import os
import re
from dataclasses import dataclass, field

import h5py
import numpy as np

from disc_profiles import guiding_centre_drift
from report_images import column_density_at_particles, extent_quantile, frame_half_width
from ring_model import is_ring_run

PROFILE_QUANTILE = 0.999      # a disc's bins reach out to this quantile of the radii
DIAG_COLUMNS = ["step", "time", "tau", "dt", "particles", "mass", "accreted_mass", "kinetic_energy",
                "internal_energy", "angular_momentum", "accreted_angular_momentum", "wall_time"]
SNAPSHOT_RE = re.compile(r"^snapshot_(\d{3,})\.hdf5$")


class UsageError(Exception):
    """Bad input directory: reported with exit status 2."""


def find_snapshots(run_dir):
    """Snapshot paths of a run directory, in output order."""
    if not os.path.isdir(run_dir):
        raise UsageError(f"run directory '{run_dir}' does not exist")
    found = []
    for name in os.listdir(run_dir):
        m = SNAPSHOT_RE.match(name)
        if m:
            found.append((int(m.group(1)), os.path.join(run_dir, name)))
    if not found:
        raise UsageError(f"no snapshot_*.hdf5 files in '{run_dir}'")
    return [path for _, path in sorted(found)]


def plain(value):
    """HDF5 attribute value as a plain Python value (bytes decoded, 1-element arrays unwrapped)."""
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "S":
            value = np.char.decode(value, "utf-8", "replace")
        return value.item() if value.size == 1 else value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def read_attrs(path, group):
    with h5py.File(path, "r") as f:
        if group not in f:
            return None
        return {str(k): plain(v) for k, v in f[group].attrs.items()}


def read_header(path):
    header = read_attrs(path, "Header")
    if header is None:
        raise ValueError(f"{path}: no /Header group")
    return header


def read_positions(f):
    """x-y positions relative to the central mass: Coordinates minus Header/PointMassPosition where
    a file has it (files in the box layout yt reads), else as stored."""
    pos = np.asarray(f["PartType0/Coordinates"][:], dtype=float)
    pos = pos.reshape(len(pos), -1)
    header = f["Header"].attrs if "Header" in f else {}
    if "PointMassPosition" in header:
        pos = pos - np.asarray(header["PointMassPosition"], dtype=float).reshape(-1)[: pos.shape[1]]
    return pos[:, :2]


def vectors(gas, name):
    """x-y components of a vector dataset (3 or 2 columns), None where absent."""
    if name not in gas:
        return None
    v = np.asarray(gas[name][:], dtype=float)
    return v.reshape(len(v), -1)[:, :2]


# sigma_2 w(0) of the 2D kernels (src/physics/kernels.hpp): the self term of the summation density
# is m sigma_2 w(0) / h^2.
SELF_WEIGHT_2D = {"cubic": 10 / (7 * math.pi), "wendland_c2": 7 / (4 * math.pi), "wendland_c4": 9 / (4 * math.pi)}


def read_particles(path):
    """Gas particles: x-y positions, radius, radial velocity, specific angular momentum j, guiding-centre
    drift (None without Acceleration), Sigma, the self-term-free Sigma and h (None without
    SmoothingLength) and masses. Sigma is Density in a 2D run; in a 3D run (Header
    SimulationDimension 3), whose Density is a volume density, each particle's column density seen
    from above with the 2D cubic spline (report_images.column_density_at_particles)."""
    with h5py.File(path, "r") as f:
        gas = f["PartType0"]
        xy, vel, acc = read_positions(f), vectors(gas, "Velocities"), vectors(gas, "Acceleration")
        sigma = np.asarray(gas["Density"][:], dtype=float)
        mass = np.asarray(gas["Masses"][:], dtype=float)
        h = np.asarray(gas["SmoothingLength"][:], dtype=float) if "SmoothingLength" in gas else None
        kernel = f["Parameters"].attrs.get("sph.kernel", b"cubic") if "Parameters" in f else b"cubic"
        kernel = (kernel.decode() if isinstance(kernel, bytes) else str(kernel)).strip('"')
        three_d = int(plain(f["Header"].attrs.get("SimulationDimension", 2))) == 3
    if three_d and h is not None:
        sigma, kernel = column_density_at_particles(xy, mass, h), "cubic"
    r = np.hypot(xy[:, 0], xy[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        vr = (xy[:, 0] * vel[:, 0] + xy[:, 1] * vel[:, 1]) / r
        noself = sigma - mass * SELF_WEIGHT_2D.get(kernel, SELF_WEIGHT_2D["cubic"]) / h**2 if h is not None else None
    return {"xy": xy, "r": r, "vr": vr, "j": xy[:, 0] * vel[:, 1] - xy[:, 1] * vel[:, 0],
            "drift": guiding_centre_drift(xy, vel, acc) if acc is not None else None,
            "sigma": sigma, "sigma_noself": noself, "h": h, "mass": mass, "column": three_d and h is not None}


def survey(snapshots, r0):
    """Radii over all snapshots, from their positions alone: (frame half-width of the maps in r0,
    smallest radius, largest PROFILE_QUANTILE radius)."""
    quantiles, r_min, r_max = [], math.inf, 0.0
    for path in snapshots:
        with h5py.File(path, "r") as f:
            xy = read_positions(f)
        r = np.hypot(xy[:, 0], xy[:, 1])
        if len(r):
            quantiles.append(extent_quantile(xy, r0))
            r_min, r_max = min(r_min, float(r.min())), max(r_max, float(np.quantile(r, PROFILE_QUANTILE)))
    return frame_half_width(quantiles), (r_min if r_min < math.inf else 0.0), r_max


def read_csv_columns(path, required):
    """Columns of a CSV file as float arrays; None when absent, empty or lacking a required column."""
    if not os.path.isfile(path):
        return None
    with open(path, newline="") as fh:
        rows = [row for row in csv.DictReader(fh) if row]
    if not rows or any(c not in rows[0] for c in required):
        return None
    return {c: np.array([to_float(row.get(c)) for row in rows]) for c in rows[0] if c is not None}


def to_float(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def read_json(path, kind):
    """A JSON file's content when it is of the expected kind (dict or list), else None."""
    if not os.path.isfile(path):
        return None
    with open(path) as fh:
        data = json.load(fh)
    return data if isinstance(data, kind) else None


@dataclass
class Run:
    """What the report knows about a run directory before the snapshots' particles are read."""
    run_dir: str
    snapshots: list
    headers: list
    params: dict
    units: dict | None
    ring_run: bool
    r0: float
    diag: dict | None = None
    timers: dict | None = None
    ranks: list | None = None
    figures: list = field(default_factory=list)   # (caption, file name)
    notes: list = field(default_factory=list)


def check_one_run(snapshots, headers):
    """Refuses snapshots of different runs side by side (Header RunID, which sphdisk derives from the
    settings that decide the results; files without one are not compared)."""
    ids = {}
    for path, header in zip(snapshots, headers):
        run_id = header.get("RunID")
        if run_id:
            ids.setdefault(str(run_id), os.path.basename(path))
    if len(ids) > 1:
        (a, fa), (b, fb) = list(ids.items())[:2]
        raise UsageError(f"snapshots of different runs in one directory: {fa} (run {a}) and {fb} (run {b}); "
                         "rerun with --overwrite, or move one run's files elsewhere")


def load_run(run_dir):
    """Snapshot list, headers, the first snapshot's /Parameters and /Units, and the run's CSV and JSON
    files; r0 is Header RingRadius, else the code length unit."""
    snapshots = find_snapshots(run_dir)
    headers = [read_header(p) for p in snapshots]
    check_one_run(snapshots, headers)
    params = read_attrs(snapshots[0], "Parameters") or {}
    ring_run = is_ring_run(headers[0], params)
    r0 = float(headers[0].get("RingRadius") or 1.0)
    return Run(run_dir, snapshots, headers, params, read_attrs(snapshots[0], "Units"), ring_run, r0,
               diag=read_csv_columns(os.path.join(run_dir, "diagnostics.csv"), DIAG_COLUMNS),
               timers=read_json(os.path.join(run_dir, "timers.json"), dict),
               ranks=read_json(os.path.join(run_dir, "ranks.json"), list))


def conservation_series(diag):
    """Relative changes of the conserved quantities in diagnostics.csv."""
    mass = diag["mass"] + diag["accreted_mass"]
    ang = diag["angular_momentum"] + diag["accreted_angular_momentum"]
    energy = diag["kinetic_energy"] + diag["internal_energy"]
    return [
        ("(mass + accreted) / M₀ - 1", relative_change(mass)),
        ("accreted mass / M₀", diag["accreted_mass"] / mass[0] if mass[0] else diag["accreted_mass"]),
        ("(L_z + accreted L_z) / L₀ - 1", relative_change(ang)),
        ("(E_kin + E_int) / E₀ - 1\n(no potential energy)", relative_change(energy)),
    ]


def relative_change(values):
    """values / values[0] - 1, or the plain change where the first value is 0."""
    ref = values[0]
    return values / ref - 1.0 if ref else values - ref


def largest_change(values):
    """max |values/values[0] - 1| over the finite rows, None where there are none."""
    change = np.abs(relative_change(values))
    change = change[np.isfinite(change)]
    return float(change.max()) if change.size else None

