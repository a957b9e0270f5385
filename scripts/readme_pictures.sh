#!/bin/sh
# The README's three pictures of the default model (docs/img/), from a fresh run of it:
# the layers and the total maximum shear strain of the last increment, and the incremental
# maximum shear strain with 5x displacement vectors at increment 150.
# Usage: sh scripts/readme_pictures.sh [BUILD]   (about 15 s)
set -eu
BUILD=${1:-build}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$BUILD/cdem-run" -q -o "$TMP/default.h5"
"$BUILD/cdem-strain" render "$TMP/default.h5" --increment last --width 900 -o docs/img/default-layers.png
"$BUILD/cdem-strain" render "$TMP/default.h5" --increment last --width 900 --color total-max-shear \
    -o docs/img/default-total-max-shear.png
"$BUILD/cdem-strain" render "$TMP/default.h5" --increment 150 --width 900 --color incr-max-shear \
    --vectors incr -o docs/img/default-incr-shear-150.png
"$BUILD/cdem-strain" voids "$TMP/default.h5"
