#!/usr/bin/python3
"""Measures one finished run for the examples' comparison tables (make: OUT/NAME-measures.md).

usage: measure.py CDEM_STRAIN RUN.h5 [--wedge] [--threshold V] > NAME-measures.md

Writes a short Markdown section with what `cdem-strain` measures in the last increment:
element counts, boundary displacement, the steepest 1 km of surface, voids and open
fissures (`cdem-strain voids`), the fault zones of total maximum shear strain >= V
(`cdem-strain faults --threshold V`, default V = 1: the tables compare runs at one strain,
not at cdem-strain faults' own default, the outlier bound of each field) and, with --wedge, the wedge's height, length and
taper (`cdem-strain wedge`). Every number a README quotes about a run comes from this file.
"""
import csv
import io
import json
import os
import re
import subprocess
import sys


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("measure.py: %s failed: %s" % (" ".join(cmd), p.stderr.strip()))
    return p.stdout, p.stderr


def main(argv):
    args = argv[1:]
    wedge = "--wedge" in args
    if wedge:
        args.remove("--wedge")
    threshold = "1"
    if "--threshold" in args:
        k = args.index("--threshold")
        threshold = args[k + 1]
        del args[k : k + 2]
    if len(args) != 2:
        sys.exit(__doc__.strip().splitlines()[2])
    strain, h5 = args
    name = os.path.basename(h5)[: -len(".h5")]

    info = json.loads(run([strain, "info", "--json", h5])[0])
    first, last = info["increments"][0], info["increments"][-1]
    m = re.search(r"free elements:\s+(\d+)", info["summary"])
    free0 = int(m.group(1)) if m else None
    boundary = first["elements"] - free0 if free0 is not None else 0
    free_last = last["elements"] - boundary
    m = re.search(r"radii:\s+(full|half|[\d.e+-]+-[\d.e+-]+ units \(([\d.e+-]+) x)", info["summary"])
    radii = ("default" if not m or m.group(1) == "full" else "half" if m.group(1) == "half"
             else "%s x the default" % m.group(2))
    out = ["### %s" % name, ""]
    out.append(
        "- run: %s radii, %d free elements at the start, %d at the end; %d increments; "
        "boundary displacement %.0f m; %s (%s)"
        % (radii, free0 or 0, free_last, info["increment_count"], last["net_displacement"],
           info["stop_reason"], info["stop_detail"])
    )

    voids = run([strain, "voids", h5])[0]
    slope = re.search(r"steepest surface slope = ([\d.]+) deg", voids).group(1)
    nvoid = re.search(r"voids = (\d+)", voids).group(1)
    fiss = re.search(r"deepest open fissure = ([\d.e+-]+) m", voids).group(1)
    out.append(
        "- surface: steepest 1 km %s°; voids %s; deepest open fissure %.0f m"
        % (slope, nvoid, float(fiss))
    )

    text, summary = run([strain, "faults", h5, "--threshold", threshold])
    zones = list(csv.DictReader(io.StringIO(text)))
    cell = re.search(r"cells of ([\d.e+-]+) m", summary).group(1)
    left = sum(1 for z in zones if z["dips"] == "left")
    out.append(
        "- fault zones (total max shear >= %s, cells of %s m, spanning >= 4 cells): %d "
        "(%d dip left, %d dip right)" % (threshold, cell, len(zones), left, len(zones) - left)
    )
    if zones:
        out.append("")
        out.append("  | zone | top x, y (km) | bottom x, y (km) | dip | dips | mean / max |")
        out.append("  |---|---|---|---|---|---|")
        for z in zones:
            out.append(
                "  | %s | %.2f, %.2f | %.2f, %.2f | %.0f° | %s | %.2g / %.2g |"
                % (z["zone"], float(z["x_top"]) / 1e3, float(z["y_top"]) / 1e3,
                   float(z["x_bottom"]) / 1e3, float(z["y_bottom"]) / 1e3, float(z["dip"]),
                   z["dips"], float(z["mean"]), float(z["max"]))
            )
        out.append("")

    if wedge:
        text = run([strain, "wedge", h5, "--increment", "last"])[0]
        rows = list(csv.DictReader(io.StringIO(text)))
        if rows:
            r = rows[-1]
            out.append(
                "- wedge: shortening %.0f m (%.1f %%), height %.0f m, deformed length %.0f m, "
                "taper %.1f°" % (float(r["shortening_m"]), float(r["shortening_percent"]),
                                 float(r["height_m"]), float(r["length_m"]), float(r["taper_deg"]))
            )
    out.append("")
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main(sys.argv)
