"""Column-density maps of a snapshot: the SPH sum Sigma(x) = sum_j m_j W(|x - x_j|, h_j) on a pixel grid.

W is the 2D cubic spline (docs/physics.md sec. 2, "Kernels"), support 2 h_j, with each particle's own
SmoothingLength. Particles are handled in groups of equal footprint (pixels within 2 h), each group in
chunks whose footprints are summed into the grid with np.bincount, so 1M particles on 512^2 pixels
take seconds.
"""
import math

import matplotlib.colors as mcolors
import matplotlib.pyplot as plt
import numpy as np

from report_style import COLUMN_IMAGE, DPI, X_LABEL, Y_LABEL, save

PIXELS = 512
CHUNK_ELEMENTS = 1 << 21     # kernel evaluations per chunk: bounds the temporary arrays (~16 MB each)
DECADES = 3.5                # colour range of the maps below their common maximum
EXTENT_QUANTILE = 0.999      # the frame holds this fraction of the particles of every snapshot
EXTENT_STEP = 0.25           # frame half-width rounded up to a multiple of this (in r0)


def cubic_w(q):
    """Dimensionless 2D cubic spline w(q) = [(2-q)_+^3 - 4 (1-q)_+^3] / 4 (w(0) = 1)."""
    return 0.25 * (np.clip(2.0 - q, 0.0, None) ** 3 - 4.0 * np.clip(1.0 - q, 0.0, None) ** 3)


def column_density_at_particles(xy, mass, h):
    """Each particle's column density Sigma_i = sum_j m_j W(|xy_i - xy_j|, h_i), W the 2D cubic spline
    (sigma_2 = 10 / (7 pi)) over the particles' positions seen from above: a 3D run's surface density
    per particle (its Density is a volume density). The partners come from a k-d tree, k doubled
    for the particles whose k-th partner is still inside 2 h_i."""
    from scipy.spatial import cKDTree
    tree = cKDTree(xy)
    sigma = np.empty(len(xy))
    todo, k = np.arange(len(xy)), 128
    while len(todo):
        k = min(k, len(xy))
        short = []
        for chunk in np.array_split(todo, len(todo) * k // CHUNK_ELEMENTS + 1):
            d, j = tree.query(xy[chunk], k=k)
            d, j = d.reshape(len(chunk), -1), j.reshape(len(chunk), -1)
            sigma[chunk] = 10.0 / (7.0 * math.pi) * (cubic_w(d / h[chunk, None]) * mass[j]).sum(axis=1) / h[chunk] ** 2
            short.append(chunk[d[:, -1] < 2.0 * h[chunk]])
        todo = np.concatenate(short) if k < len(xy) else todo[:0]
        k *= 2
    return sigma


def footprint_weights(px, py, h_pix, k):
    """Kernel weights (n, 2k+1, 2k+1) of n particles at pixel coordinates (px, py) with smoothing
    lengths h_pix (in pixels), on the pixels within k of the nearest one, and those pixels' indices."""
    off = np.arange(-k, k + 1)
    ix = np.rint(px).astype(np.int64)[:, None] + off
    iy = np.rint(py).astype(np.int64)[:, None] + off
    ddx = (ix - px[:, None]) / h_pix[:, None]
    ddy = (iy - py[:, None]) / h_pix[:, None]
    q = np.sqrt(ddx[:, None, :] ** 2 + ddy[:, :, None] ** 2)
    return cubic_w(q), ix, iy


def deposit(grid, px, py, mass, h_pix, k, npix):
    """Adds particles of footprint half-width k pixels to the flat grid (mass per pixel).

    Each particle's weights are normalised to its mass, so that the map conserves mass where h is
    below the pixel size (for resolved particles the factor differs from 1 by the midpoint error);
    a particle whose support holds no pixel centre goes into its nearest pixel."""
    w, ix, iy = footprint_weights(px, py, h_pix, k)
    total = w.sum(axis=(1, 2))
    empty = total <= 0
    if empty.any():
        w[empty, k, k] = 1.0
        total[empty] = 1.0
    w *= (mass / total)[:, None, None]
    inside = ((iy >= 0) & (iy < npix))[:, :, None] & ((ix >= 0) & (ix < npix))[:, None, :]
    flat = iy[:, :, None] * npix + ix[:, None, :]
    grid += np.bincount(flat[inside], weights=w[inside], minlength=npix * npix)


def render_column_density(xy, mass, h, half_width, npix=PIXELS):
    """Sigma on npix x npix pixels over [-half_width, half_width]^2 (row index = y), in the units of
    mass / length^2 of the inputs."""
    dx = 2.0 * half_width / npix
    px = (xy[:, 0] + half_width) / dx - 0.5   # pixel i has its centre at -half_width + (i + 1/2) dx
    py = (xy[:, 1] + half_width) / dx - 0.5
    h_pix = np.asarray(h, dtype=float) / dx
    k = np.ceil(2.0 * h_pix).astype(np.int64)
    seen = (px + k >= -0.5) & (px - k <= npix - 0.5) & (py + k >= -0.5) & (py - k <= npix - 0.5) & (h_pix > 0)
    grid = np.zeros(npix * npix)
    for kk in np.unique(k[seen]):
        sel = np.flatnonzero(seen & (k == kk))
        chunk = max(1, CHUNK_ELEMENTS // (2 * int(kk) + 1) ** 2)
        for s in range(0, len(sel), chunk):
            i = sel[s:s + chunk]
            deposit(grid, px[i], py[i], mass[i], h_pix[i], int(kk), npix)
    return grid.reshape(npix, npix) / dx**2


def frame_half_width(radii_quantiles):
    """Half-width (in r0) of a square frame holding EXTENT_QUANTILE of the particles of every snapshot."""
    q = max([r for r in radii_quantiles if np.isfinite(r)] or [1.0])
    return EXTENT_STEP * math.ceil(1.05 * q / EXTENT_STEP)


def extent_quantile(xy, r0):
    """EXTENT_QUANTILE of |x|/r0 and |y|/r0 over the particles (input to frame_half_width)."""
    return float(np.quantile(np.abs(xy) / r0, EXTENT_QUANTILE)) if len(xy) else math.nan


def sigma_unit(units):
    """Factor from code units of Sigma to g cm^-2 and the colour-bar label; code units where /Units is absent."""
    mass, length = (units or {}).get("UnitMass_in_g"), (units or {}).get("UnitLength_in_cm")
    if mass and length:
        return float(mass) / float(length) ** 2, r"$\Sigma$ (g cm$^{-2}$)"
    return 1.0, r"$\Sigma$ ($M\,r_0^{-2}$, code units)"


def common_norm(images):
    """Log colour scale shared by the maps: from DECADES below the largest pixel to it."""
    top = max((float(np.max(im)) for im in images if im.size and np.max(im) > 0), default=1.0)
    return mcolors.LogNorm(vmin=top * 10.0**-DECADES, vmax=top, clip=False)


def image_axes(figsize):
    """Square map axes and a colour-bar axes beside it at fixed positions (inches), so that the colour
    bar is as tall as the map."""
    w, h = figsize
    left, bottom, side, gap, bar = 0.5, 0.45, h - 0.6, 0.08, 0.12
    fig = plt.figure(figsize=figsize, dpi=DPI)
    ax = fig.add_axes([left / w, bottom / h, side / w, side / h])
    cax = fig.add_axes([(left + side + gap) / w, bottom / h, bar / w, side / h])
    return fig, ax, cax


def plot_column_density(image, half_width, norm, label, note, path):
    """One map: x/r0, y/r0 axes, log colour scale, colour bar with units; empty pixels take the lowest colour."""
    cmap = plt.get_cmap("inferno")
    cmap = cmap.with_extremes(under=cmap(0.0), bad=cmap(0.0))
    fig, ax, cax = image_axes(COLUMN_IMAGE)
    shown = np.ma.masked_less_equal(image, 0.0)
    im = ax.imshow(shown, origin="lower", extent=(-half_width, half_width, -half_width, half_width),
                   norm=norm, cmap=cmap, interpolation="nearest")
    ax.set(xlabel=X_LABEL, ylabel=Y_LABEL, aspect="equal")
    fig.colorbar(im, cax=cax, label=label, extend="min")
    ax.text(0.03, 0.97, note, transform=ax.transAxes, ha="left", va="top", fontsize=7, color="white")
    save(fig, path)
