#!/usr/bin/python3
"""Write a small synthetic sphdisk run directory (for tests of the analysis tools only).

    make_test_run.py OUTDIR [--particles N] [--taus 0.018,0.036,...] [--noise 0.05] [--seed 1]
                            [--scaling] [--no-diagnostics] [--disc [--times 0,20,40] [--inflow V]]

The layout mirrors what `sphdisk run` writes (docs/formats.md, "Snapshot files"):
OUTDIR/snapshot_000.hdf5 (tau = first value of --taus), snapshot_001.hdf5, ... in the
GADGET-4/SWIFT HDF5 layout (Coordinates in [0, BoxSize]^3 around Header/PointMassPosition), plus
OUTDIR/diagnostics.csv and, with --scaling, OUTDIR/scaling.csv.

Particles are drawn from the analytic viscous-ring solution (P98 eqs. 11-12, code units G = M = r0 = 1)
at each tau: radii by inverse CDF of r Sigma(r), uniform azimuth, Keplerian + analytic radial velocity.
`Density` is the analytic Sigma times (1 + noise * N(0, 1)), standing in for an SPH estimate, and
`Acceleration` is gravity plus the azimuthal part whose torque makes the guiding-centre drift
2 j (x a_y - y a_x) equal the analytic v_r.
With --disc the snapshots hold instead a power-law disc, Sigma ~ 1/r for 0.5 <= r <= 2, on Kepler
orbits with a uniform radial velocity -V (--inflow, default 0; its drift is -V too), at the times of
--times, with Header Problem = "disc" and no ring attributes.
The analytic formulas are implemented here independently of tools/report.py on purpose, so the
report test cross-checks the two.
"""
import argparse
import csv
import math
import os
import sys

import h5py
import numpy as np
from scipy.integrate import trapezoid
from scipy.special import ive

# Paper units: r0 = 1 Rsun, M = 1 Msun, nu = 3e-8 Rsun^2/s; code units G = M = r0 = 1.
RSUN_CM = 6.957e10
MSUN_G = 1.98841e33
G_CGS = 6.6743e-8
UNIT_TIME_S = math.sqrt(RSUN_CM**3 / (G_CGS * MSUN_G))
NU_CODE = 3e-8 * UNIT_TIME_S  # 3e-8 Rsun^2/s in code units (Rsun^2 / time unit): ~4.778e-5
DISK_MASS = 1e-10
R_ACCRETION = 0.05


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("outdir")
    p.add_argument("--particles", type=int, default=4000)
    p.add_argument("--taus", default="0.018,0.036,0.054,0.072,0.09",
                   help="comma-separated viscous times, one snapshot each (first = initial conditions)")
    p.add_argument("--noise", type=float, default=0.05, help="relative Gaussian noise on Density")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--scaling", action="store_true", help="also write a synthetic scaling.csv")
    p.add_argument("--no-diagnostics", action="store_true", help="do not write diagnostics.csv")
    p.add_argument("--disc", action="store_true", help="a power-law disc instead of the ring")
    p.add_argument("--times", default="0,20,40", help="--disc: comma-separated snapshot times (code units)")
    p.add_argument("--inflow", type=float, default=0.0, help="--disc: uniform inward radial velocity V")
    args = p.parse_args(argv)
    args.taus = [float(t) for t in args.taus.split(",") if t.strip()]
    args.times = [float(t) for t in args.times.split(",") if t.strip()]
    return args


def sigma_ring(x, tau, mass=DISK_MASS):
    """Analytic surface density (P98 eq. 11) at x = r / r0, r0 = 1."""
    z = 2.0 * x / tau
    return mass / (math.pi * tau) * x**-0.25 * np.exp(-(1.0 - x) ** 2 / tau) * ive(0.25, z)


def vr_ring(x, tau, nu=NU_CODE):
    """Analytic radial velocity (P98 eq. 12) at x = r / r0, r0 = 1."""
    z = 2.0 * x / tau
    return 6.0 * nu / tau * (x - ive(-0.75, z) / ive(0.25, z))


def sample_radii(rng, n, tau):
    """Radii >= R_ACCRETION by inverse CDF of 2 pi r Sigma(r) on a fine grid."""
    r = np.linspace(R_ACCRETION, 4.0, 40001)
    pdf = r * sigma_ring(r, tau)
    cdf = np.concatenate(([0.0], np.cumsum(0.5 * (pdf[1:] + pdf[:-1]) * np.diff(r))))
    cdf /= cdf[-1]
    return np.interp(rng.random(n), cdf, r)


def accreted_fraction(tau):
    """Fraction of the disc mass inside R_ACCRETION."""
    r = np.linspace(1e-6, R_ACCRETION, 2001)
    inner = trapezoid(2 * math.pi * r * sigma_ring(r, tau), r)
    return inner / DISK_MASS


def kepler_particles(rng, r, vr):
    """Positions, velocities and accelerations at radii r (uniform azimuth) on Kepler orbits with radial
    velocity vr; the azimuthal acceleration vr / (2 r^1.5) gives the guiding-centre drift 2 j r a_phi = vr."""
    n = len(r)
    phi = rng.uniform(0.0, 2 * math.pi, n)
    cphi, sphi = np.cos(phi), np.sin(phi)
    vphi = r**-0.5
    a_r, a_phi = -(r**-2.0), vr / (2.0 * r**1.5)
    pos = np.column_stack((r * cphi, r * sphi, np.zeros(n)))
    vel = np.column_stack((vr * cphi - vphi * sphi, vr * sphi + vphi * cphi, np.zeros(n)))
    acc = np.column_stack((a_r * cphi - a_phi * sphi, a_r * sphi + a_phi * cphi, np.zeros(n)))
    return pos, vel, acc


def make_particles(rng, n, tau, noise):
    """Positions, velocities, accelerations and SPH-like density for n particles at viscous time tau."""
    r = sample_radii(rng, n, tau)
    pos, vel, acc = kepler_particles(rng, r, vr_ring(r, tau))
    sigma = sigma_ring(r, tau) * (1.0 + noise * rng.standard_normal(n))
    return pos, vel, acc, sigma


DISC_RANGE = (0.5, 2.0)   # power-law disc: Sigma = DISK_MASS / (3 pi r) on this range (r0 = 1)


def sigma_disc(r):
    return DISK_MASS / (3.0 * math.pi * r)


def disc_accretion_rate(inflow):
    """Mass flux 2 pi r Sigma V of the power-law disc: the same through every radius."""
    return 2.0 * DISK_MASS * inflow / 3.0


def make_disc_particles(rng, n, inflow, noise):
    """The power-law disc: r Sigma is constant, so radii are uniform on DISC_RANGE."""
    r = rng.uniform(*DISC_RANGE, n)
    pos, vel, acc = kepler_particles(rng, r, np.full(n, -inflow))
    sigma = sigma_disc(r) * (1.0 + noise * rng.standard_normal(n))
    return pos, vel, acc, sigma


def run_parameters(args):
    """Stand-in for the resolved configuration written to /Parameters."""
    if args.disc:
        return {"problem.particles": args.particles, "problem.seed": args.seed,
                "problem.initial_conditions": "disc_initial.hdf5", "physics.dimension": 2,
                "physics.accretion_radius": R_ACCRETION, "sph.kernel": "cubic", "integrator.scheme": "leapfrog",
                "output.directory": os.path.basename(os.path.abspath(args.outdir))}
    return {
        "problem.name": "ring",
        "problem.particles": args.particles,
        "problem.seed": args.seed,
        "problem.disk_mass": DISK_MASS,
        "problem.ring_radius": 1.0,
        "physics.dimension": 2,
        "physics.viscosity": NU_CODE,
        "physics.accretion_radius": R_ACCRETION,
        "sph.kernel": "wendland_c4",
        "sph.smoothing_length": smoothing_length(args.particles),
        "integrator.scheme": "leapfrog",
        "output.tau": np.array(args.taus[1:] or args.taus, dtype=np.float64),
        "output.directory": os.path.basename(os.path.abspath(args.outdir)),
    }


def smoothing_length(n):
    """Support 2h = 0.09 r0 at N = 1e4, scaled as N^-1/2 (docs/physics.md sec. 4)."""
    return 0.045 * math.sqrt(1e4 / n)


def fixed_string(s):
    """Fixed-length ASCII string attribute (yt calls .decode() on Header/Code: no variable-length str)."""
    return np.bytes_(s.encode("ascii"))


def attr_value(v):
    return fixed_string(v) if isinstance(v, str) else v


def round_up_short(w):
    """w rounded up to 4 significant bits, as sphdisk rounds the box (src/io/snapshot.cpp)."""
    step = math.ldexp(1.0, math.frexp(w)[1] - 4)
    return math.ceil(w / step) * step


def box_size(pos, h):
    """BoxSize as sphdisk writes it: twice the largest |x_c| + 2 h, rounded up (every kernel inside)."""
    return 2.0 * round_up_short(float(np.max(np.abs(pos))) + 2.0 * h)


def write_header(f, n, time, accreted_mass, box, ring_attrs=None, problem=None):
    """/Header of docs/formats.md, in the layout yt's SWIFT frontend reads (Code "SWIFT" as a fixed-length
    string, BoxSize of 3 values, Dimension 3); the central mass sits at the box centre.
    ring_attrs: the ring's ViscousTime, KinematicViscosity, RingRadius, DiskMass; problem: Header Problem."""
    h = f.create_group("Header")
    npart = np.array([n, 0, 0, 0, 0, 0], dtype=np.uint64)
    h.attrs["NumPart_ThisFile"] = npart
    h.attrs["NumPart_Total"] = npart
    h.attrs["NumPart_Total_HighWord"] = np.zeros(6, dtype=np.uint32)
    h.attrs["MassTable"] = np.zeros(6, dtype=np.float64)
    h.attrs["Time"] = np.float64(time)
    h.attrs["Redshift"] = np.float64(0.0)
    h.attrs["BoxSize"] = np.full(3, box, dtype=np.float64)
    h.attrs["PointMassPosition"] = np.full(3, box / 2, dtype=np.float64)
    h.attrs["NumFilesPerSnapshot"] = np.int32(1)
    h.attrs["Dimension"] = np.int32(3)
    h.attrs["SimulationDimension"] = np.int32(2)
    h.attrs["Code"] = fixed_string("SWIFT")
    h.attrs["CodeName"] = fixed_string("sphdisk")
    if problem is not None:
        h.attrs["Problem"] = fixed_string(problem)
    for key, value in (ring_attrs or {}).items():
        h.attrs[key] = np.float64(value)
    h.attrs["AccretedMass"] = np.float64(accreted_mass)


def write_units(f):
    u = f.create_group("Units")
    u.attrs["UnitLength_in_cm"] = np.float64(RSUN_CM)
    u.attrs["UnitMass_in_g"] = np.float64(MSUN_G)
    u.attrs["UnitTime_in_s"] = np.float64(UNIT_TIME_S)
    u.attrs["UnitVelocity_in_cm_per_s"] = np.float64(RSUN_CM / UNIT_TIME_S)
    u.attrs["Unit length in cgs (U_L)"] = np.float64(RSUN_CM)
    u.attrs["Unit mass in cgs (U_M)"] = np.float64(MSUN_G)
    u.attrs["Unit time in cgs (U_t)"] = np.float64(UNIT_TIME_S)
    u.attrs["Unit temperature in cgs (U_T)"] = np.float64(1.0)
    u.attrs["Unit current in cgs (U_I)"] = np.float64(1.0)


def write_swift_groups(f):
    """The groups yt's SWIFT frontend opens: open boundaries, no cosmology, empty scheme groups."""
    f.create_group("RuntimePars").attrs["PeriodicBoundariesOn"] = np.int64(0)
    f.create_group("Policy").attrs["cosmological integration"] = np.int64(0)
    f.create_group("HydroScheme")
    f.create_group("SubgridScheme")


def write_parameters(f, params):
    g = f.create_group("Parameters")
    for key, value in params.items():
        g.attrs[key] = attr_value(value)


def write_gas(f, pos, vel, acc, sigma, mass_each, h, centre):
    n = len(sigma)
    g = f.create_group("PartType0")
    g.create_dataset("Coordinates", data=pos.astype(np.float64) + centre)
    g.create_dataset("Velocities", data=vel.astype(np.float64))
    g.create_dataset("Acceleration", data=acc.astype(np.float64))
    g.create_dataset("Masses", data=np.full(n, mass_each, dtype=np.float64))
    g.create_dataset("ParticleIDs", data=np.arange(1, n + 1, dtype=np.uint64))
    g.create_dataset("SmoothingLength", data=np.full(n, h, dtype=np.float64))
    g.create_dataset("Density", data=sigma.astype(np.float64))


def write_snapshot(path, rng, args, tau, params):
    n = args.particles
    frac = accreted_fraction(tau)
    pos, vel, acc, sigma = make_particles(rng, n, tau, args.noise)
    ring = {"ViscousTime": tau, "KinematicViscosity": NU_CODE, "RingRadius": 1.0, "DiskMass": DISK_MASS}
    h = smoothing_length(n)
    box = box_size(pos, h)
    with h5py.File(path, "w") as f:
        write_header(f, n, tau / (12.0 * NU_CODE), frac * DISK_MASS, box, ring_attrs=ring)
        write_units(f)
        write_parameters(f, params)
        write_swift_groups(f)
        write_gas(f, pos, vel, acc, sigma, DISK_MASS * (1.0 - frac) / n, h, box / 2)


def disc_accreted(args, time):
    return disc_accretion_rate(args.inflow) * (time - args.times[0])


def write_disc_snapshot(path, rng, args, time, params):
    """A power-law disc snapshot: adaptive-like h ~ (m / Sigma)^1/2, Header Problem = "disc"."""
    n = args.particles
    accreted = disc_accreted(args, time)
    pos, vel, acc, sigma = make_disc_particles(rng, n, args.inflow, args.noise)
    mass_each = (DISK_MASS - accreted) / n
    h = 1.3 * np.sqrt(mass_each / sigma_disc(np.hypot(pos[:, 0], pos[:, 1])))
    box = box_size(pos, float(np.max(h)))
    with h5py.File(path, "w") as f:
        write_header(f, n, time, accreted, box, problem="disc")
        write_units(f)
        write_parameters(f, params)
        write_swift_groups(f)
        write_gas(f, pos, vel, acc, sigma, mass_each, h, box / 2)


DIAG_COLUMNS = ["step", "time", "tau", "dt", "particles", "mass", "accreted_mass", "kinetic_energy",
                "internal_energy", "angular_momentum", "accreted_angular_momentum", "wall_time"]


def write_diagnostics(path, taus, n, rows=25, time_of=lambda tau: tau / (12 * NU_CODE),
                      accreted=lambda tau: DISK_MASS * accreted_fraction(tau)):
    """Plausible per-step diagnostics: tiny drifts on top of the analytic disc's totals. taus: the
    snapshots' viscous times (for the disc: their times, written in both columns)."""
    tau_grid = np.linspace(taus[0], taus[-1], rows)
    ke0 = 0.5 * DISK_MASS * 1.0  # v^2 ~ 1/r near r0
    l0 = DISK_MASS * 1.0
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(DIAG_COLUMNS)
        for step, tau in enumerate(tau_grid):
            acc = accreted(tau)
            s = (tau - taus[0]) / max(taus[-1] - taus[0], 1e-30)
            w.writerow([step * 100, time_of(tau), tau, 0.02, n, DISK_MASS - acc, acc,
                        ke0 * (1 + 1e-3 * s), 1e-6 * ke0 * s, l0 * (1 - 1e-4 * s) - acc * 0.2,
                        acc * 0.2, 0.5 + 10.0 * s])


def write_scaling(path):
    """Synthetic strong-scaling table: Amdahl-like timings with a communication share."""
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["workers", "particles", "wall_time", "comm_time"])
        for n, serial in ((10000, 0.10), (100000, 0.03), (500000, 0.01)):
            t1 = 1e-4 * n
            for p in (1, 2, 4, 8, 16):
                comm = 0.0 if p == 1 else 0.02 * t1 * math.log2(p) / p
                w.writerow([p, n, t1 * (serial + (1 - serial) / p) + comm, comm])


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if not (args.times if args.disc else args.taus) or args.particles < 1:
        print("make_test_run.py: need at least one output time and one particle", file=sys.stderr)
        return 2
    os.makedirs(args.outdir, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    params = run_parameters(args)
    outputs = args.times if args.disc else args.taus
    for i, value in enumerate(outputs):
        write = write_disc_snapshot if args.disc else write_snapshot
        write(os.path.join(args.outdir, f"snapshot_{i:03d}.hdf5"), rng, args, value, params)
    if not args.no_diagnostics:
        diag = os.path.join(args.outdir, "diagnostics.csv")
        if args.disc:
            write_diagnostics(diag, args.times, args.particles, time_of=lambda t: t,
                              accreted=lambda t: disc_accreted(args, t))
        else:
            write_diagnostics(diag, args.taus, args.particles)
    if args.scaling:
        write_scaling(os.path.join(args.outdir, "scaling.csv"))
    print(f"wrote {len(outputs)} snapshots of {args.particles} particles to {args.outdir}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
