#!/usr/bin/python3
"""The three stages of the paper's Fig. 14 in one run, and the null point at each (make:
OUT/fig14-stages.md and OUT/fig14-stages.txt).

usage: stages.py CDEM_STRAIN RUN.h5 OUTDIR > fig14-stages.md

Stages, from the run's increments (`cdem-strain info --json`):
  max    the maximum normal displacement, just before the inversion (the increment with the
         largest net displacement);
  half   50 % inversion: the first increment after it whose net displacement is at most half
         the maximum;
  full   100 % inversion: the first increment after it whose net displacement is at most 0
         (or the last increment, with the inversion reached, when the run ends before).
Writes OUTDIR/fig14-stages.txt ("max K", "half K", "full K": the increments, and "zoom
XMIN,XMAX,YMIN,YMAX": the view box of the pictures, for make) and, on stdout, a Markdown
section: each stage's increment, net displacement and element count beside the paper's,
and the null point at each.

The view box (`cdem-strain render --zoom`, m) holds every free element (layer > 0: neither
wall, base nor fault; `cdem-strain export-sspx`) of the three stages, grown by MARGIN of its
larger side (the walls beside and below them show): one box for the four pictures of the
montage, so that they share the scale (the layers picture keeps the colour bar's room,
`--colour-bar-space`), and not the box of every element, which holds the fault line
running about 2.4 km below the model (40 % of each picture).

The null point (Williams et al., 1989): along the fault, where the hanging-wall beds pass
from net subsidence (below) to net uplift (above). The fault at a height is the left edge of
the pre-growth hanging wall there (the elements that sank by more than half the block's
throw at the maximum normal displacement); the band is the hanging-wall and growth-strata
elements within BAND m right of it, in BIN m slices, with their mean uplift (`cdem-strain
compute --quantity uplift`: the height now minus the height at the end of equilibration,
or at the increment it was deposited in for a growth element); the null point is the
lowest height above which every slice's mean uplift is positive, given above the base and
below the band's top.
"""
import csv
import io
import json
import math
import os
import subprocess
import sys
import tempfile

BAND = 300.0  # m, the hanging-wall band along the fault plane
BIN = 100.0   # m, height of a slice
MARGIN = 0.02  # of the view box's larger side (cdem-strain render's own fit margin)
PAPER = {"initial": 46335, "max": 54288, "half": 55665, "full": 55855}


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("stages.py: %s failed: %s" % (" ".join(cmd), p.stderr.strip()))
    return p.stdout


def params_of(info):
    """The parameter values a run file stores (the summary's lines are not parsed)."""
    out = {}
    for line in info["summary"].splitlines():
        if ":" in line:
            k, v = line.split(":", 1)
            out[k.strip()] = v.strip()
    return out


def elements(strain, h5, inc, quantity):
    """{id: (x, y, value)} of one increment (`cdem-strain compute`)."""
    text = run([strain, "compute", h5, "--increment", str(inc), "--quantity", quantity])
    rows = list(csv.reader(io.StringIO(text)))
    ii, ix, iy, iv = (rows[0].index(c) for c in ("id", "x", "y", "value"))
    out = {}
    for r in rows[1:]:
        out[int(r[ii])] = (float(r[ix]), float(r[iy]), float(r[iv]))
    return out


def view_box(strain, h5, numbers):
    """The box (xmin, xmax, ymin, ymax, m) of the free elements' discs (layer > 0) of the
    given increments, grown by MARGIN of its larger side (`cdem-strain export-sspx`: id x y
    radius layer; layer 0 is a wall, base or fault element)."""
    x0 = y0 = math.inf
    x1 = y1 = -math.inf
    with tempfile.TemporaryDirectory() as tmp:
        for k in numbers:
            run([strain, "export-sspx", h5, "--increments", "%d-%d" % (k, k), "--prefix",
                 "view", tmp])
            with open(os.path.join(tmp, "view%d.txt" % k)) as f:
                for line in f:
                    _, x, y, r, layer = line.split()
                    if int(layer) <= 0:
                        continue
                    x, y, r = float(x), float(y), float(r)
                    x0, x1 = min(x0, x - r), max(x1, x + r)
                    y0, y1 = min(y0, y - r), max(y1, y + r)
    if not x1 > x0:
        sys.exit("stages.py: no free elements in increments %s" % numbers)
    m = MARGIN * max(x1 - x0, y1 - y0)
    return x0 - m, x1 + m, y0 - m, y1 + m


def null_point(hanging, initial, growth, now):
    """The null point in one increment (`now`: {id: (x, y, uplift)}). hanging: the ids of the
    pre-growth hanging wall; initial: the ids of the initial assembly's free elements; growth:
    the ids of the growth strata (the walls are in neither). The fault at a height is the left edge of the hanging wall there (the leftmost
    hanging-wall element of the slice; above the pre-growth, the line fitted to the edges of
    its upper half, extended); the band is the elements of the hanging wall and the growth
    strata within BAND m right of it."""
    edge = {}
    for i in hanging:
        if i in now:
            x, y, _ = now[i]
            k = int(y // BIN)
            edge[k] = min(edge.get(k, 1e30), x)
    if len(edge) < 2:
        return None
    ks = sorted(edge)
    upper = ks[len(ks) // 2:]
    n = len(upper)
    my = sum(k * BIN for k in upper) / n
    mx = sum(edge[k] for k in upper) / n
    sxy = sum((k * BIN - my) * (edge[k] - mx) for k in upper)
    syy = sum((k * BIN - my) ** 2 for k in upper)
    slope = sxy / syy if syy > 0 else 0.0
    def fault_x(k):
        return edge[k] if k in edge else mx + slope * (k * BIN - my)
    slices = {}
    top = -1e30
    for i, (x, y, v) in now.items():
        if math.isnan(v) or (i in initial and i not in hanging) or (
                i not in initial and i not in growth):
            continue
        k = int(y // BIN)
        if 0.0 <= x - fault_x(k) <= BAND:
            slices.setdefault(k, []).append(v)
            top = max(top, y)
    if not slices:
        return None
    means = {k: sum(v) / len(v) for k, v in slices.items()}
    ks = sorted(means)
    null_k = None
    for i, k in enumerate(ks):
        if all(means[j] > 0.0 for j in ks[i:]):
            null_k = k
            break
    profile = [(k * BIN, means[k], len(slices[k])) for k in ks]
    if null_k is None:
        return {"height": None, "depth": None, "profile": profile}
    h = null_k * BIN
    return {"height": h, "depth": top - h, "profile": profile}


def main(argv):
    if len(argv) != 4:
        sys.exit(__doc__.strip().splitlines()[3])
    strain, h5, outdir = argv[1], argv[2], argv[3]
    info = json.loads(run([strain, "info", h5, "--json"]))
    incs = info["increments"]
    p = params_of(info)
    dip = float(p["fault dip"].split()[0])
    k_max = max(range(len(incs)), key=lambda i: incs[i]["net_displacement"])
    d_max = incs[k_max]["net_displacement"]
    k_half = next((i for i in range(k_max, len(incs))
                   if incs[i]["net_displacement"] <= 0.5 * d_max), len(incs) - 1)
    k_full = next((i for i in range(k_max, len(incs))
                   if incs[i]["net_displacement"] <= 0.0), len(incs) - 1)
    stages = {"max": k_max, "half": k_half, "full": k_full}
    with open(os.path.join(outdir, "fig14-stages.txt"), "w") as f:
        for name, k in stages.items():
            f.write("%s %d\n" % (name, incs[k]["number"]))
        f.write("zoom %.1f,%.1f,%.1f,%.1f\n" % view_box(
            strain, h5, [incs[k]["number"] for k in stages.values()]))
    print("## Fig. 14: the three stages (stages.py, from %s)" % os.path.basename(h5))
    print()
    print("| stage | increment | net displacement (m) | inversion | elements | paper | ours / paper |")
    print("|---|---|---|---|---|---|---|")
    print("| initial assembly | %d | 0 | - | %d | %d | %.3f |" % (
        incs[0]["number"], incs[0]["elements"], PAPER["initial"],
        incs[0]["elements"] / PAPER["initial"]))
    labels = {"max": "maximum normal displacement", "half": "50 % inversion",
              "full": "100 % inversion"}
    for name, k in stages.items():
        net = incs[k]["net_displacement"]
        inv = 100.0 * (d_max - net) / d_max if d_max > 0 else 0.0
        print("| %s | %d | %.1f | %.0f %% | %d | %d | %.3f |" % (
            labels[name], incs[k]["number"], net, inv, incs[k]["elements"], PAPER[name],
            incs[k]["elements"] / PAPER[name]))
    print()
    at_max = elements(strain, h5, incs[k_max]["number"], "uplift")
    initial = set(elements(strain, h5, incs[0]["number"], "incr-disp-x"))
    drop = 0.5 * d_max * math.sin(math.radians(dip))
    first = elements(strain, h5, incs[0]["number"], "incr-disp-x")
    growth = {i for i in elements(strain, h5, incs[-1]["number"], "incr-disp-x") if i not in first}
    # walls, the fault ramps and the base have no strain (NaN): they are not beds
    strained = {i for i, (x, y, v) in elements(strain, h5, incs[k_max]["number"],
                                               "total-max-shear").items() if not math.isnan(v)}
    initial &= strained
    hanging = {i for i, (x, y, v) in at_max.items() if i in initial and v < -drop}
    print("Null point (Williams et al., 1989): the lowest height above which the hanging-wall "
          "beds along the fault have net uplift in every %.0f m slice. The fault at a height "
          "is the left edge of the pre-growth hanging wall (the elements that had sunk by more "
          "than half the block's %.0f m at the maximum normal displacement: %d of them); the "
          "band is the hanging-wall and growth-strata elements within %.0f m right of it; "
          "uplift is `cdem-strain compute --quantity uplift` (the growth strata's from the "
          "increment they were deposited in)." % (BIN, d_max * math.sin(math.radians(dip)),
                                                  len(hanging), BAND))
    print()
    print("| stage | null point above the base (m) | below the band's top (m) | slices (height: mean uplift m, elements) |")
    print("|---|---|---|---|")
    for name in ("max", "half", "full"):
        now = at_max if name == "max" else elements(strain, h5, incs[stages[name]]["number"],
                                                     "uplift")
        r = null_point(hanging, initial, growth, now)
        if r is None:
            print("| %s | no elements in the band | | |" % labels[name])
            continue
        prof = "; ".join("%.0f: %+.0f (%d)" % (h, v, n) for h, v, n in r["profile"])
        print("| %s | %s | %s | %s |" % (
            labels[name], "none" if r["height"] is None else "%.0f" % r["height"],
            "" if r["depth"] is None else "%.0f" % r["depth"], prof))


if __name__ == "__main__":
    main(sys.argv)
