#!/usr/bin/python3
"""Contact statistics of a dump (ITEM: ATOMS id type x y radius ...) for bench/lammps_bench.sh.

Counts the touching pairs (distance < r_i + r_j) that involve at least one free element
(type 1): frozen-frozen pairs (type 2) never interact in either code. Prints
"contacts N mean_overlap M max_overlap X" (overlap = r_i + r_j - distance, m).
Usage: lammps_overlap.py DUMP [DUMP2]: with two dumps, also the largest position
difference between equal ids."""
import sys

import numpy as np
from scipy.spatial import cKDTree


def load(path):
    with open(path) as f:
        lines = f.read().splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("ITEM: ATOMS"))
    a = np.array([[float(v) for v in line.split()[:5]] for line in lines[start + 1:] if line.strip()])
    return a[np.argsort(a[:, 0])]


def stats(a):
    xy, r, t = a[:, 2:4], a[:, 4], a[:, 1]
    pairs = cKDTree(xy).query_pairs(2.0 * r.max(), output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    d = np.hypot(*(xy[i] - xy[j]).T)
    ov = r[i] + r[j] - d
    keep = (ov > 0) & ~((t[i] == 2) & (t[j] == 2))
    return keep.sum(), ov[keep].mean(), ov[keep].max()


for path in sys.argv[1:]:
    n, mean, mx = stats(load(path))
    print(f"contacts {n} mean_overlap {mean:.6g} max_overlap {mx:.6g}  ({path})")
if len(sys.argv) == 3:
    a, b = load(sys.argv[1]), load(sys.argv[2])
    if a.shape == b.shape and (a[:, 0] == b[:, 0]).all():
        print(f"max_position_difference {np.abs(a[:, 2:4] - b[:, 2:4]).max():.6g}")
