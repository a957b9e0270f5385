#!/bin/sh
# Benchmarks (make bench). Builds bench/bench_solver.c against the libraries of BUILD and
# runs it on the default model for OMP_NUM_THREADS=1 and 2: one line each with
# element-steps per second (docs/performance.md records the figures).
# Usage: sh bench/run_bench.sh [BUILD] [deformation_steps]
BUILD=${1:-build}
STEPS=${2:-20000}
PKGS="hdf5 gsl"
CFLAGS="-O2 -g -std=c17 -Wall -Wextra -Werror -fopenmp -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -Icommon -Isolver"
set -e
cc $CFLAGS $(pkg-config --cflags $PKGS) -o "$BUILD/bench_solver" bench/bench_solver.c \
    "$BUILD/libcdemsolver.a" "$BUILD/libcdem.a" $(pkg-config --libs $PKGS) -lm
for t in 1 2; do
    printf 'bench_solver OMP_NUM_THREADS=%s: ' "$t"
    OMP_NUM_THREADS=$t "$BUILD/bench_solver" "$STEPS"
done
