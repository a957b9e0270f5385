#!/usr/bin/python3
"""Writes the small cdem2D-style folders used by tests/test_cdem2d.c (run from the
repository root; the output is committed, rerun only on purpose).

cdem2d_basic/      LF endings: 4 increments (0..3) of 30 elements + 6 wall elements; every
                   increment shifts free elements by dx = 5 + 0.02 y (m); element 7 vanishes
                   from increment 2; two growth elements (layer 4) appear in increment 3,
                   whose rows are written in reverse order.
cdem2d_crlf/       the same with CRLF endings and modelforces_N.txt (sxx = 1e6 (i + 1),
                   syy = 2e6, sxy = 0.5e6, for original element i).
cdem2d_malformed/  modelresults_1.txt line 3 holds a non-number.
"""
import os

def elements():
    out = []
    for r in range(5):
        for c in range(6):
            rad = 50.0 if (r + c) % 2 == 0 else 75.0
            out.append([100.0 + 180.0 * c + 90.0 * (r % 2), 100.0 + 156.0 * r, rad, 1 + r // 2])
    walls = [[50.0 + 200.0 * c, -50.0, 50.0, 0] for c in range(6)]
    return out, walls

def increment(k):
    els, walls = elements()
    rows = []
    for i, e in enumerate(els):
        if k >= 2 and i == 7:
            continue
        x, y, rad, lay = e
        for step in range(1, k + 1):
            x += 5.0 + 0.02 * y
        rows.append((i, [x, y, rad, lay]))
    for j, w in enumerate(walls):
        rows.append((100 + j, w))
    if k == 3:
        rows.append((200, [400.0, 900.0, 50.0, 4]))
        rows.append((201, [560.0, 900.0, 50.0, 4]))
        rows.reverse()
    return rows

PARAMS = """cdem2D model parameters (test fixture)
Pre-growth layers = 3
Faulting mode: planar normal fault
Equilibration increment = 1
Unit scaling = 1000
"""

def write(folder, eol, forces):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "modelparameters.txt"), "w", newline="") as f:
        f.write(PARAMS.replace("\n", eol))
    for k in range(4):
        rows = increment(k)
        with open(os.path.join(folder, "modelresults_%d.txt" % k), "w", newline="") as f:
            for i, (x, y, rad, lay) in rows:
                f.write("%.6f %.6f %.4f %d%s" % (x, y, rad, lay, eol))
        if forces:
            with open(os.path.join(folder, "modelforces_%d.txt" % k), "w", newline="") as f:
                for i, _ in rows:
                    f.write("%.1f %.1f %.1f%s" % (1e6 * (i + 1), 2e6, 0.5e6, eol))

write("tests/data/cdem2d_basic", "\n", False)
write("tests/data/cdem2d_crlf", "\r\n", True)
os.makedirs("tests/data/cdem2d_malformed", exist_ok=True)
with open("tests/data/cdem2d_malformed/modelparameters.txt", "w") as f:
    f.write(PARAMS)
with open("tests/data/cdem2d_malformed/modelresults_0.txt", "w") as f:
    f.write("100 100 50 1\n200 100 50 1\n300 100 50 1\n")
with open("tests/data/cdem2d_malformed/modelresults_1.txt", "w") as f:
    f.write("100 100 50 1\n200 100 50 1\n300.0 abc 50 1\n")
