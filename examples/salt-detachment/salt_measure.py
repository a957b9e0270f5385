#!/usr/bin/python3
"""The salt's shape in one run of examples/salt-detachment (make: OUT/NAME-salt.md).

usage: salt_measure.py RUN.h5 > NAME-salt.md

Reads the run file with h5py (docs/format.md, "Layout") and measures, at the end of
equilibration (the last increment of the equilibration phase) and at the last increment, in columns COL m
wide over the part of the model that holds salt:
  salt top       the highest top (y + r) of the salt elements of a column;
  salt base      the lowest bottom (y - r) of its salt elements;
  thickness      top minus base (a column without salt between two with salt: 0, a weld);
  cover base     the lowest bottom of the free cover elements above the salt's top;
  gap            cover base minus salt top: the open strip between the two;
  surface        the highest top of the free elements of a column.
And the salt body's area: the salt discs drawn on a PIXEL m raster, closed (dilated, then
eroded) by a disc of half the salt's mean radius so that the pores between touching discs
count as salt, and not the open ground around the body, and its holes filled (a hole is
inside the body, whether the elements around it spread or another body's elements fill it). It is a geometric measure, unlike
the series' salt_area (the salt's own material area, sum of J pi r^2 / phi, which only the
grid's velocity divergence changes): when salt elements crowd onto each other (they have
no repulsion between them, docs/solver.md section 9) the body shrinks while salt_area does
not.
Writes a Markdown section: the salt's crest (the highest salt top, its x and its rise above
the mean salt top at the end of equilibration; the cover's thickness over it), the salt's
thickness range, welds, the mean and largest gap, and the lowest surface (a graben's floor)
with its x. Every number the README quotes about the salt comes from this file.
"""
import sys

import h5py
import numpy as np
from scipy import ndimage

COL = 250.0  # m, column width
PIXEL = 10.0  # m, the raster of the salt body's area
SALT = 1 << 10
BOUNDARY = (1 << 0) | (1 << 1) | (1 << 6) | (1 << 7)  # wall, fault, footwall, mylar


def increment(f, k):
    ix = f["increments/index"][k]
    o, n = int(ix["offset"]), int(ix["n"])
    xy = f["increments/xy"][o:o + n]
    return {
        "x": xy[:, 0], "y": xy[:, 1], "r": f["increments/radius"][o:o + n],
        "flags": f["increments/flags"][o:o + n], "net": float(ix["net_displacement"]),
        "number": int(ix["number"]), "phase": int(ix["phase"]),
    }


def columns(inc, x0, x1):
    """Per column of [x0, x1): salt top, salt base, cover base above the salt, surface."""
    salt = (inc["flags"] & SALT) != 0
    free = (inc["flags"] & BOUNDARY) == 0
    cover = free & ~salt
    nc = max(1, int(np.ceil((x1 - x0) / COL)))
    out = []
    for c in range(nc):
        lo, hi = x0 + c * COL, x0 + (c + 1) * COL
        inside = (inc["x"] >= lo) & (inc["x"] < hi)
        s, v, fr = inside & salt, inside & cover, inside & free
        top = float(np.max(inc["y"][s] + inc["r"][s])) if s.any() else np.nan
        base = float(np.min(inc["y"][s] - inc["r"][s])) if s.any() else np.nan
        above = v & (inc["y"] > (top if np.isfinite(top) else -np.inf))
        cbase = float(np.min(inc["y"][above] - inc["r"][above])) if above.any() else np.nan
        surf = float(np.max(inc["y"][fr] + inc["r"][fr])) if fr.any() else np.nan
        out.append((0.5 * (lo + hi), top, base, cbase, surf))
    return np.array(out)


def body_area(inc):
    """The salt body's area (m^2): its discs rasterised and closed (module docstring)."""
    s = (inc["flags"] & SALT) != 0
    x, y, r = inc["x"][s], inc["y"][s], inc["r"][s]
    pad = 2.0 * r.max()
    x0, y0 = (x - r).min() - pad, (y - r).min() - pad
    nx = int(((x + r).max() + pad - x0) / PIXEL) + 1
    ny = int(((y + r).max() + pad - y0) / PIXEL) + 1
    img = np.zeros((ny, nx), bool)
    for xi, yi, ri in zip(x, y, r):
        a0, a1 = int((xi - ri - x0) / PIXEL), int((xi + ri - x0) / PIXEL) + 1
        b0, b1 = int((yi - ri - y0) / PIXEL), int((yi + ri - y0) / PIXEL) + 1
        gx, gy = np.meshgrid(x0 + (np.arange(a0, a1) + 0.5) * PIXEL,
                             y0 + (np.arange(b0, b1) + 0.5) * PIXEL)
        img[b0:b1, a0:a1] |= (gx - xi) ** 2 + (gy - yi) ** 2 <= ri * ri
    k = max(1, int(round(0.5 * r.mean() / PIXEL)))
    yy, xx = np.mgrid[-k:k + 1, -k:k + 1]
    disc = xx * xx + yy * yy <= k * k
    closed = ndimage.binary_fill_holes(ndimage.binary_closing(img, structure=disc))
    return float(closed.sum()) * PIXEL * PIXEL


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__.strip().splitlines()[2])
    with h5py.File(argv[1], "r") as f:
        ix = f["increments/index"][:]
        equil = [k for k in range(len(ix)) if int(ix["phase"][k]) == 0]  # equilibration
        k0 = equil[-1] if equil else 0
        first, last = increment(f, k0), increment(f, len(ix) - 1)
    sx = lambda inc: inc["x"][(inc["flags"] & SALT) != 0]
    if sx(first).size == 0:
        print("No salt in %s." % argv[1])
        return
    x0 = min(sx(first).min(), sx(last).min()) - COL
    x1 = max(sx(first).max(), sx(last).max()) + COL
    print("### The salt in %s\n" % argv[1])
    print("Columns of %g m; at the end of equilibration (increment %d) and at the last "
          "increment (%d, net displacement %.0f m).\n" % (COL, first["number"], last["number"],
                                                         last["net"]))
    print("| | end of equilibration | last increment |")
    print("|---|---|---|")
    c0, c1 = columns(first, x0, x1), columns(last, x0, x1)
    mean_top0 = np.nanmean(c0[:, 1])
    rows = []
    for c in (c0, c1):
        has = np.isfinite(c[:, 1])
        k = int(np.nanargmax(c[:, 1]))
        thick = np.where(has, c[:, 1] - c[:, 2], 0.0)
        span = np.flatnonzero(has)
        inner = thick[span[0]:span[-1] + 1] if span.size else thick
        gap = c[:, 3] - c[:, 1]
        gap = gap[np.isfinite(gap)]
        surf = np.where(has, c[:, 4], np.nan)  # columns with salt: not the model's ends
        ks = int(np.nanargmin(surf))
        rows.append({
            "crest": "%.0f m at x = %.1f km" % (c[k, 1], c[k, 0] / 1000.0),
            "rise": "%.0f m" % (c[k, 1] - mean_top0),
            "over": "%.0f m" % (c[k, 4] - c[k, 1]) if np.isfinite(c[k, 4]) else "none (at the surface)",
            "mean_top": "%.0f m" % np.nanmean(c[:, 1]),
            "thick": "%.0f–%.0f m" % (np.min(inner), np.max(inner)),
            "welds": "%d" % int(np.sum(inner == 0.0)),
            "gap": "%.0f m / %.0f m" % (np.mean(gap), np.max(gap)) if gap.size else "—",
            "surface": "%.0f m at x = %.1f km" % (c[ks, 4], c[ks, 0] / 1000.0),
        })
    a0, a1 = body_area(first), body_area(last)
    rows[0]["body"] = "%.3f km²" % (a0 / 1e6)
    rows[1]["body"] = "%.3f km² (%+.1f %%)" % (a1 / 1e6, 100.0 * (a1 / a0 - 1.0))
    for key, label in (("body", "salt body's area (closed raster, module docstring)"),
                       ("crest", "salt crest (highest salt top)"),
                       ("rise", "crest above the mean salt top at the end of equilibration"),
                       ("over", "cover over the crest"),
                       ("mean_top", "mean salt top"),
                       ("thick", "salt thickness (columns between the salt's ends)"),
                       ("welds", "welds (columns without salt between salt)"),
                       ("gap", "open strip between salt top and cover base, mean / largest"),
                       ("surface", "lowest surface (a graben's floor)")):
        print("| %s | %s | %s |" % (label, rows[0][key], rows[1][key]))


if __name__ == "__main__":
    main(sys.argv)
