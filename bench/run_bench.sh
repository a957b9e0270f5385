#!/bin/sh
# Benchmarks (make bench). Builds bench/bench_solver.c against the libraries of BUILD and
# runs it on the default model (and a large one) for OMP_NUM_THREADS=1 and 2: one line each with
# element-steps per second (docs/performance.md records the figures).
# Usage: sh bench/run_bench.sh [BUILD] [deformation_steps]
BUILD=${1:-build}
STEPS=${2:-20000}
PKGS="hdf5 gsl"
CFLAGS="-O2 -g -std=c17 -Wall -Wextra -Werror -fopenmp -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -Icommon -Isolver"
set -e
# The build box is shared: with the default (spinning) OpenMP wait policy an idle thread
# burns the CPU the working one needs, which makes 2 threads slower than 1 under load.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
cc $CFLAGS $(pkg-config --cflags $PKGS) -o "$BUILD/bench_solver" bench/bench_solver.c \
    "$BUILD/libcdemsolver.a" "$BUILD/libcdem.a" $(pkg-config --libs $PKGS) -lm
for t in 1 2; do
    printf 'bench_solver default model, OMP_NUM_THREADS=%s: ' "$t"
    OMP_NUM_THREADS=$t "$BUILD/bench_solver" "$STEPS"
done
# a large model (100 x 5 units, half radii, ~85,000 elements), where the loops are threaded
for t in 1 2; do
    printf 'bench_solver 100 x 5 half radii, OMP_NUM_THREADS=%s: ' "$t"
    OMP_NUM_THREADS=$t "$BUILD/bench_solver" 500 2000 100 1
done
# side by side with LAMMPS on the same settled packing (installs Debian's lammps if missing)
sh bench/lammps_bench.sh "$BUILD"
