#!/usr/bin/python3
"""Ripples in a ring's radial mass profile (docs/validation.md, "What makes the core clump"): counts
the particles in fine radial bins over 0.7-1.3 r0, divides their departure from a Gaussian-smoothed
profile (sigma 0.025 r0) by the counting noise, and reports the rms of that ratio (1 for independent
random radii) and the power at wavelengths 0.03-0.2 r0 over the mean power of all wavelengths (1 for
noise), with the wavelength of its peak. A coherent radial wave shows as a band ratio well above 1.

Usage: bench/radial_ripples.py SNAPSHOT.hdf5 [SNAPSHOT.hdf5 ...]
"""
import pathlib
import sys

import h5py
import numpy as np
from scipy.ndimage import gaussian_filter1d

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "tools"))
from snapshot_positions import positions  # noqa: E402  (Coordinates relative to the central mass)

BIN = 0.005  # r0


def ripples(path):
    with h5py.File(path, "r") as f:
        x = positions(f, 2)
        r0 = float(f["Header"].attrs.get("RingRadius", 1.0))
    r = np.hypot(x[:, 0], x[:, 1]) / r0
    counts, _ = np.histogram(r, np.arange(0.7, 1.3 + BIN / 2, BIN))
    counts = counts.astype(float)
    smooth = gaussian_filter1d(counts, 0.025 / BIN)
    ratio = ((counts - smooth) / np.sqrt(smooth))[15:-15]  # away from the window's edges
    power = np.abs(np.fft.rfft(ratio - ratio.mean())) ** 2
    k = np.fft.rfftfreq(len(ratio), BIN)
    band = (k > 1 / 0.2) & (k < 1 / 0.03)
    return ratio.std(), power[band].mean() / power[1:].mean(), 1 / k[band][np.argmax(power[band])]


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__.split("\n\n")[-1].strip())
    for path in sys.argv[1:]:
        rms, band, peak = ripples(path)
        print(f"{path}: rms / noise {rms:.2f}, power at 0.03-0.2 r0 / mean {band:.1f} (peak at {peak:.3f} r0)")


if __name__ == "__main__":
    main()
