#!/bin/sh
# The main job on the built-in default model: simulate, then analyse and render.
# Grows with the product; every step that exists is run.
set -eu
BUILD=${1:-build}
OUT=${CDEM_DEMO_OUT:-out}
mkdir -p "$OUT"
"$BUILD/cdem-run" --summary
