"""Stress of a settled assembly under gravity: sigma_yy ~ rho g depth.

Reads the end-of-equilibration increment of a run made with physics.calculate_stress = on
and compares the mean sigma_yy of free elements in depth bands (away from the lateral
walls) with rho * g * depth. Why rho and not the bulk density: the per-element
Love-Weber stress divides by the disc area pi r^2, not by the element's share of the
packing (disc area / packing fraction), so it is the bulk stress / packing fraction, and
rho_bulk / packing fraction = rho. Tolerance 15 %: wall friction carries part of the
weight near the base (silo effect) and the top band is one or two elements thick.
Usage: /usr/bin/python3 check_stress_column.py RUN.h5 [DENSITY] [GRAVITY]
"""
import sys

import os

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import cdemfile  # noqa: E402

path = sys.argv[1]
rho = float(sys.argv[2]) if len(sys.argv) > 2 else 2500.0
g = float(sys.argv[3]) if len(sys.argv) > 3 else 9.81
with h5py.File(path, "r") as f:
    inc = [i for i in cdemfile.increments(f) if int(i.attrs["phase"]) == 0][-1]
    x, y, syy, flags = (np.asarray(inc[n][:]) for n in ("x", "y", "syy", "flags"))
free = (flags & (1 | 2 | 64 | 128)) == 0  # not wall, fault, footwall or mylar
top = np.percentile(y[free], 99.5)
depth = top - y
xmin, xmax = x[free].min(), x[free].max()
inner = free & (x > xmin + 0.1 * (xmax - xmin)) & (x < xmax - 0.1 * (xmax - xmin))
worst = 0.0
for lo, hi in [(0.1, 0.2), (0.2, 0.4), (0.4, 0.6), (0.6, 0.8), (0.8, 0.95)]:
    span = depth[free].max()
    band = inner & (depth >= lo * span) & (depth < hi * span)
    ratio = np.mean(syy[band]) / (rho * g * np.mean(depth[band]))
    print(f"depth {lo:.2f}-{hi:.2f} of the column: sigma_yy / (rho g depth) = {ratio:.3f}")
    worst = max(worst, abs(ratio - 1.0))
assert worst < 0.15, f"sigma_yy differs from rho g depth by {worst:.0%} (allowed 15 %)"
print(f"sigma_yy within {worst:.1%} of rho g depth (allowed 15 %)")
