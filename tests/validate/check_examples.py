#!/usr/bin/python3
"""Asserts the measurable features of the paper's figures on the reduced-size example runs
(make validate, after `make -C examples quick`), so that a regression in the physics fails:

  planar/fig7a-normal30   a graben: a fault zone dipping right (synthetic) and one dipping
                          left (antithetic) to its right; no void; no cliff (steepest
                          1 km of surface below 60 degrees)
  planar/fig7b-reverse50  a fault zone rising from the fault tip; no void
  planar/fig7c-caldera    at least two fault zones, one each way; no void
  growth/fig12a-...       more than one fault zone (thrusts), and an undeformed foreland:
                          the deformed wedge shorter than 85 % of the belt
  salt-detachment/...     (issue 37, not the paper) the salt keeps its body: its geometric
                          area (salt_measure.py) within 20 % of the end of equilibration's in
                          both quick runs; the shortened salt thickens (its mean top rises);
                          the wedge over salt has a lower taper than its twin without salt

usage: check_examples.py CDEM_STRAIN EXAMPLES_OUT
(EXAMPLES_OUT is the folder `make -C examples quick EXAMPLES_OUT=...` wrote into.)
The thresholds are total maximum shear strains suited to the quick runs' displacement
(about a third of the paper's); docs/analysis.md "Fault zones".
"""
import csv
import io
import os
import re
import subprocess
import sys


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("check_examples: FAIL: %s: %s" % (" ".join(cmd), p.stderr.strip()))
    return p.stdout


def zones(strain, h5, threshold):
    return list(csv.DictReader(io.StringIO(run([strain, "faults", h5, "--threshold",
                                                  str(threshold)]))))


def voids(strain, h5):
    text = run([strain, "voids", h5])
    return (int(re.search(r"voids = (\d+)", text).group(1)),
            float(re.search(r"steepest surface slope = ([\d.]+)", text).group(1)))


def salt_checks(strain, out, check):
    """examples/salt-detachment's quick runs (docs/solver.md 9.5: before J followed the field
    that moves the salt, the contraction's salt body lost 61 % and its mean top fell)."""
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path.insert(0, os.path.join(here, "..", "..", "examples", "salt-detachment"))
    import h5py
    import numpy as np
    import salt_measure as sm
    tops = {}
    for name in ("ext-salt", "con-salt"):
        with h5py.File(os.path.join(out, "salt-detachment", name + ".h5"), "r") as f:
            ix = f["increments/index"][:]
            equil = [k for k in range(len(ix)) if int(ix["phase"][k]) == 0]
            first, last = sm.increment(f, equil[-1] if equil else 0), sm.increment(f, len(ix) - 1)
        a0, a1 = sm.body_area(first), sm.body_area(last)
        check(abs(a1 / a0 - 1.0) <= 0.2, "salt %s: body %.2f -> %.2f km2 (%+.1f %%)" %
              (name, a0 / 1e6, a1 / 1e6, 100.0 * (a1 / a0 - 1.0)))
        salt = lambda inc: (inc["flags"] & sm.SALT) != 0
        x0 = min(first["x"][salt(first)].min(), last["x"][salt(last)].min()) - sm.COL
        x1 = max(first["x"][salt(first)].max(), last["x"][salt(last)].max()) + sm.COL
        tops[name] = (np.nanmean(sm.columns(first, x0, x1)[:, 1]),
                      np.nanmean(sm.columns(last, x0, x1)[:, 1]))
    t0, t1 = tops["con-salt"]
    check(t1 > t0, "salt con-salt: mean salt top %.0f -> %.0f m (the shortened salt thickens)" %
          (t0, t1))
    taper = {}
    for name in ("con-salt", "con-nosalt"):
        h5 = os.path.join(out, "salt-detachment", name + ".h5")
        w = list(csv.DictReader(io.StringIO(run([strain, "wedge", h5, "--increment", "last"]))))
        taper[name] = float(w[-1]["taper_deg"])
    check(taper["con-salt"] < taper["con-nosalt"], "salt: taper %.1f deg over salt, %.1f without"
          % (taper["con-salt"], taper["con-nosalt"]))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[-4])
    strain, out = sys.argv[1:]
    problems, lines = [], []

    def check(ok, what):
        (lines if ok else problems).append(what)

    h5 = os.path.join(out, "planar", "fig7a-normal30.h5")
    z = zones(strain, h5, 0.2)
    n_void, slope = voids(strain, h5)
    right = [float(a["x_top"]) for a in z if a["dips"] == "right"]
    left = [float(a["x_top"]) for a in z if a["dips"] == "left"]
    graben = bool(right and left and max(left) > min(right))
    check(graben, "7A graben: synthetic tops %s, antithetic tops %s (m)" % (right, left))
    check(n_void == 0, "7A voids %d" % n_void)
    check(slope < 60.0, "7A steepest 1 km %.1f deg" % slope)

    h5 = os.path.join(out, "planar", "fig7b-reverse50.h5")
    z = zones(strain, h5, 0.5)
    check(len(z) >= 1, "7B fault zones %d" % len(z))
    check(voids(strain, h5)[0] == 0, "7B no void")

    h5 = os.path.join(out, "planar", "fig7c-caldera.h5")
    z = zones(strain, h5, 0.5)
    dips = {a["dips"] for a in z}
    check(len(z) >= 2 and dips == {"left", "right"}, "7C fault zones %d, dipping %s" %
          (len(z), sorted(dips)))
    check(voids(strain, h5)[0] == 0, "7C no void")

    h5 = os.path.join(out, "growth", "fig12a-ftb-no-growth.h5")
    z = zones(strain, h5, 0.5)
    check(len(z) > 1, "12A fault zones %d" % len(z))
    w = list(csv.DictReader(io.StringIO(run([strain, "wedge", h5, "--increment", "last"]))))[-1]
    belt = float(w["wall_x_m"])  # the belt runs from the fixed left wall (x = 0) to here
    frac = float(w["length_m"]) / belt
    check(frac < 0.85, "12A deformed length %.0f m of a %.0f m belt (%.0f %%)" %
          (float(w["length_m"]), belt, 100 * frac))

    salt_checks(strain, out, check)

    for line in lines:
        print("check_examples: ok: " + line)
    if problems:
        for p in problems:
            print("check_examples: FAIL: " + p)
        sys.exit(1)
    print("check_examples: %d features as in the paper" % len(lines))


if __name__ == "__main__":
    main()
