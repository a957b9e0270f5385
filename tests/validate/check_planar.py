#!/usr/bin/python3
"""Checks a finished planar-fault run file (cdem-run output) against the kinematics the
solver promises (docs/solver.md): increment counts, the equilibration/deformation split,
the hanging-wall block displaced along the dip by the net displacement, the footwall walls
unmoved, no element lost silently. Exits 1 with a message on the first failed check.

usage: check_planar.py FILE.h5 --equil N --total N --dip DEG --sense normal|reverse
                       [--net-fraction F]   (expected net / gross displacement, default 1)
"""
import argparse
import math
import sys

import h5py
import numpy as np

sys.path.insert(0, __import__('os').path.dirname(__file__))
import cdemfile  # noqa: E402

FLAG_WALL, FLAG_FAULT, FLAG_MOVING = 1, 2, 4


def fail(msg):
    print("check_planar: FAIL: " + msg)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("file")
    ap.add_argument("--equil", type=int, required=True)
    ap.add_argument("--total", type=int, required=True)
    ap.add_argument("--dip", type=float, required=True)
    ap.add_argument("--sense", choices=["normal", "reverse"], required=True)
    ap.add_argument("--net-fraction", type=float, default=1.0)
    a = ap.parse_args()
    f = h5py.File(a.file, "r")
    stop = cdemfile.stop_reason(f)
    if stop != "completed":
        fail("stop_reason = %r, expected 'completed'" % stop)
    incs = cdemfile.increments(f)
    numbers = [int(g.attrs["number"]) for g in incs]
    if numbers != list(range(a.total + 1)):
        fail("increments %s..%s (%d), expected 0..%d" % (numbers[0], numbers[-1], len(numbers), a.total))
    phases = [int(g.attrs["phase"]) for g in incs]
    last_equil = max(i for i, p in enumerate(phases) if p == 0)
    if numbers[last_equil] != a.equil:
        fail("last equilibration increment is %d, expected %d" % (numbers[last_equil], a.equil))
    if any(p != 1 for p in phases[last_equil + 1:]):
        fail("phases after equilibration are not all deformation")
    first, last = incs[0], incs[-1]
    steps = [int(g.attrs["step"]) for g in incs]
    if steps != sorted(steps):
        fail("increment steps are not ascending")
    # net displacement of the moving block
    net = float(last.attrs["net_displacement"])
    dt = float(incs[1].attrs["time"]) / steps[1]
    gross = (steps[-1] - steps[last_equil]) * 25.0 * dt * dt
    # within one step: inversion at a rounded step can leave one step of net motion
    if abs(net - a.net_fraction * gross) > 1e-6 * gross + 1.0001 * 25.0 * dt * dt:
        fail("net displacement %.6f m, expected %.6f m" % (net, a.net_fraction * gross))
    d = math.radians(a.dip)
    sgn = 1.0 if a.sense == "normal" else -1.0
    ux, uy = sgn * net * math.cos(d), -sgn * net * math.sin(d)
    id0, idl = first["id"][:], last["id"][:]
    x0, y0, xl, yl = first["x"][:], first["y"][:], last["x"][:], last["y"][:]
    fl0 = first["flags"][:]
    pos = {int(i): k for k, i in enumerate(idl)}
    n_moving = n_fixed = 0
    for k, i in enumerate(id0):
        if not fl0[k] & (FLAG_WALL | FLAG_FAULT):
            continue
        j = pos.get(int(i))
        if j is None:
            fail("boundary element id %d disappeared" % i)
        dx, dy = xl[j] - x0[k], yl[j] - y0[k]
        if fl0[k] & FLAG_MOVING:
            n_moving += 1
            if abs(dx - ux) > 1e-6 * max(1.0, abs(net)) or abs(dy - uy) > 1e-6 * max(1.0, abs(net)):
                fail("moving element id %d displaced (%.6f, %.6f), expected (%.6f, %.6f)" % (i, dx, dy, ux, uy))
        else:
            n_fixed += 1
            if dx != 0.0 or dy != 0.0:
                fail("fixed boundary element id %d moved by (%g, %g)" % (i, dx, dy))
    if n_moving == 0 or n_fixed == 0:
        fail("no moving (%d) or no fixed (%d) boundary elements" % (n_moving, n_fixed))
    # every free element still inside the box (escapes are removed and logged by the solver)
    free0 = int(np.sum((fl0 & (FLAG_WALL | FLAG_FAULT)) == 0))
    free_l = int(np.sum((last["flags"][:] & (FLAG_WALL | FLAG_FAULT)) == 0))
    series_n = f["series"]["n_elements"][:] if "n_elements" in f["series"] else None
    print("check_planar: OK: %d increments (%d in equilibration), net displacement %.1f m, "
          "%d moving / %d fixed boundary elements, free elements %d -> %d (%d removed), %d series samples"
          % (len(incs) - 1, a.equil, net, n_moving, n_fixed, free0, free_l, free0 - free_l,
             0 if series_n is None else len(series_n)))
    if free0 - free_l > 0.01 * free0:
        fail("%d of %d free elements escaped (more than 1 %%)" % (free0 - free_l, free0))


if __name__ == "__main__":
    main()
