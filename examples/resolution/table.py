#!/usr/bin/python3
"""One table of what the element size changes in paper Fig. 7A (make: OUT/resolution.md;
docs/resolution.md is the paper-size output).

usage: table.py CDEM_STRAIN RUN.h5... > resolution.md

For each run (the last increment; every number from cdem-strain):
  elements      free elements at the start (`cdem-strain info --json`);
  slip          the boundary's net displacement at the end;
  synthetic / antithetic fault dip
                the longest fault zone dipping right (with the basement fault: synthetic) and
                the longest dipping left (antithetic) of the total maximum shear strain
                (`cdem-strain faults --threshold 1`: the threshold of the examples' tables, so
                the runs are compared at one strain);
  graben width  the distance between the tops of those two zones (the faults that bound
                the graben), "-" when one is missing;
  steepest km   the steepest kilometre of surface (`cdem-strain voids`).
"""
import csv
import io
import json
import re
import subprocess
import sys


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("table.py: %s failed: %s" % (" ".join(cmd), p.stderr.strip()))
    return p.stdout


def measure(strain, h5):
    info = json.loads(run([strain, "info", h5, "--json"]))
    incs = info["increments"]
    summary = info["summary"]
    radii = re.search(r"radii:\s+(.*)", summary).group(1)
    free0 = int(re.search(r"free elements:\s+(\d+)", summary).group(1))
    faults = list(csv.DictReader(io.StringIO(
        run([strain, "faults", h5, "--increment", "last", "--threshold", "1"]))))
    def longest(side):
        zs = [z for z in faults if z["dips"] == side]
        return max(zs, key=lambda z: int(z["rows"])) if zs else None
    syn, anti = longest("right"), longest("left")
    width = abs(float(anti["x_top"]) - float(syn["x_top"])) if syn and anti else None
    voids = run([strain, "voids", h5])
    slope = float(re.search(r"steepest surface slope = ([\d.]+) deg", voids).group(1))
    return {
        "radii": radii, "elements": free0, "slip": incs[-1]["net_displacement"],
        "syn": float(syn["dip"]) if syn else None, "anti": float(anti["dip"]) if anti else None,
        "width": width, "slope": slope,
    }


def main(argv):
    if len(argv) < 3:
        sys.exit(__doc__.strip().splitlines()[3])
    strain = argv[1]
    print("| radii | free elements | slip (m) | synthetic fault dip | antithetic fault dip "
          "| graben width (km) | steepest 1 km of surface |")
    print("|---|---|---|---|---|---|---|")
    for h5 in argv[2:]:
        m = measure(strain, h5)
        dip = lambda v: "none" if v is None else "%.0f°" % v
        print("| %s | %d | %.0f | %s | %s | %s | %.1f° |" % (
            m["radii"], m["elements"], m["slip"], dip(m["syn"]), dip(m["anti"]),
            "-" if m["width"] is None else "%.2f" % (m["width"] / 1000.0), m["slope"]))


if __name__ == "__main__":
    main(sys.argv)
