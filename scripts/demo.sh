#!/bin/sh
# The main job on the built-in default model (10 x 5 km, planar normal fault dipping 30
# degrees, the paper's Figure 7A set-up at default radii): simulate, analyse, render.
# Outputs go to $CDEM_DEMO_OUT (default: out/).
set -eu
BUILD=${1:-build}
OUT=${CDEM_DEMO_OUT:-out}
mkdir -p "$OUT"
# --force: a demo run of an earlier `make demo` is replaced (cdem-run keeps existing files)
"$BUILD/cdem-run" --force -o "$OUT/default.h5"
"$BUILD/cdem-strain" info "$OUT/default.h5" | grep -E "^(stop reason|increments):"
"$BUILD/cdem-strain" compute "$OUT/default.h5" --increment last --quantity total-max-shear \
    -o "$OUT/default-total-max-shear.csv"
"$BUILD/cdem-strain" render "$OUT/default.h5" --increment last -o "$OUT/default-layers.png"
"$BUILD/cdem-strain" render "$OUT/default.h5" --increment last --color total-max-shear \
    -o "$OUT/default-total-max-shear.png"
echo "demo: wrote $OUT/default.h5, $OUT/default-total-max-shear.csv, $OUT/default-layers.png and $OUT/default-total-max-shear.png"
