#!/usr/bin/python3
"""Writes a cdem2D-style simulation folder from a cdem-run file, for the shipped example
(run once by hand; the output cdem2d-inversion/ is committed):

    build/cdem-run examples/cdem2d-import/source-model.ini -o /tmp/src.h5
    /usr/bin/python3 make_folder.py /tmp/src.h5 cdem2d-inversion [EVERY]

From the end of equilibration on, every EVERY-th increment (default 10, i.e. 20 m of
fault displacement at display_interval = 2) and the last one become modelresults_N.txt
(N = 0, 1, ...; 'x y radius layer' in metres, 2 decimals, walls as layer 0; footwall
display-only and fault elements too), and modelparameters.txt gets the lines the importer
reads (docs/formats-text.md) plus the source model's summary for the record.
"""
import os
import sys

import h5py
import numpy as np


def main(src, out, every=10):
    os.makedirs(out, exist_ok=True)
    with h5py.File(src, "r") as f:
        incs = sorted(f["increments"], key=lambda k: int(f["increments"][k].attrs["number"]))
        phases = [int(f["increments"][k].attrs["phase"]) for k in incs]
        eq = max(i for i, p in enumerate(phases) if p == 0)
        chosen = list(range(eq, len(incs), every))
        if chosen[-1] != len(incs) - 1:
            chosen.append(len(incs) - 1)
        for n, i in enumerate(chosen):
            g = f["increments"][incs[i]]
            x, y, r = (np.asarray(g[k][:]) for k in ("x", "y", "radius"))
            layer = np.asarray(g["layer"][:])
            flags = np.asarray(g["flags"][:])
            wall = (flags & (1 | 2 | 64 | 128)) != 0  # CDEM_FLAGS_BOUNDARY
            keep = np.ones(len(x), bool)
            with open(os.path.join(out, f"modelresults_{n}.txt"), "w") as o:
                for k in np.nonzero(keep)[0]:
                    lay = 0 if wall[k] else int(layer[k])
                    o.write(f"{x[k]:.2f} {y[k]:.2f} {r[k]:.2f} {lay}\n")
        summary = f.attrs["summary"]
        if isinstance(summary, bytes):
            summary = summary.decode()
    with open(os.path.join(out, "modelparameters.txt"), "w") as o:
        o.write("cdem2D-format folder written by examples/cdem2d-import/make_folder.py\n")
        o.write("Pre-growth layers = 24\n")
        o.write("Faulting mode: planar normal fault with inversion\n")
        o.write("Equilibration increment = 0\n")
        o.write(f"Source increments = {' '.join(str(i) for i in chosen)}\n\n")
        o.write(summary)
    print(f"{out}: {len(chosen)} increments from {src} (source increments {chosen[0]}..{chosen[-1]})")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 10)
