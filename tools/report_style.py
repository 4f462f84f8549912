"""Figure style of the run report: journal column widths, 300 dpi PNG plus vector PDF.

Sizes are in inches (one column 3.5, two columns 7); the PNG of a figure of size (w, h) is
exactly w * DPI x h * DPI pixels, as the tests check.
"""
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend choice)

DPI = 300
COLUMN = (3.5, 2.6)           # one-column line plot
COLUMN_SQUARE = (3.5, 3.5)    # particle positions
COLUMN_IMAGE = (3.5, 2.8)     # column-density map with its colour bar
WIDE = (7.0, 2.8)             # two panels side by side
WIDE_GRID = (7.0, 5.0)        # 2 x 2 panels

STYLE = {
    "font.size": 8, "axes.labelsize": 8, "axes.titlesize": 8, "legend.fontsize": 7,
    "xtick.labelsize": 7, "ytick.labelsize": 7, "lines.linewidth": 1.0, "lines.markersize": 3,
    "axes.linewidth": 0.6, "xtick.major.width": 0.6, "ytick.major.width": 0.6,
    "legend.frameon": False, "mathtext.fontset": "dejavusans",
    "pdf.fonttype": 42,  # TrueType fonts in the PDF: editable text, as journals ask
}
plt.rcParams.update(STYLE)

R_LABEL = "$r/r_0$"
X_LABEL = "$x/r_0$"
Y_LABEL = "$y/r_0$"


def pixel_size(figsize):
    """(width, height) in pixels of the PNG of a figure of this size."""
    return round(figsize[0] * DPI), round(figsize[1] * DPI)


def new_figure(figsize=COLUMN, **kwargs):
    return plt.subplots(figsize=figsize, dpi=DPI, layout="constrained", **kwargs)


def save(fig, png_path):
    """Write the figure as PNG (DPI) and as PDF next to it, then close it."""
    fig.savefig(png_path, dpi=DPI)
    fig.savefig(os.path.splitext(png_path)[0] + ".pdf")
    plt.close(fig)


def corner_note(ax, text, loc="upper right"):
    """Small text in a corner of the axes (time of the snapshot, particle count)."""
    x, ha = (0.97, "right") if "right" in loc else (0.03, "left")
    y, va = (0.95, "top") if "upper" in loc else (0.05, "bottom")
    ax.text(x, y, text, transform=ax.transAxes, ha=ha, va=va, fontsize=7)
