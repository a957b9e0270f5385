#!/bin/sh
# Builds bench/bench_strain against the project libraries (make first), runs it and the
# numpy/scipy script, and prints the speed-up. Usage: sh bench/bench_strain.sh [BUILD]
# PYTHON selects the interpreter for the script (default: /usr/bin/python3 when it has
# scipy, else python3).
set -e
BUILD=${1:-build}
make -s "$BUILD/libcdemanalysis.a" "$BUILD/libcdem.a"
CFLAGS="-O2 -std=c17 -fopenmp -D_POSIX_C_SOURCE=200809L -Icommon -Ianalysis/measure -Ianalysis/input -Ianalysis/draw $(pkg-config --cflags gsl hdf5)"
LIBS="$(pkg-config --libs gsl hdf5) -lm -fopenmp"
cc $CFLAGS -o "$BUILD/bench_strain" bench/bench_strain.c "$BUILD/libcdemanalysis.a" "$BUILD/libcdem.a" $LIBS
if [ -z "$PYTHON" ]; then
    if /usr/bin/python3 -c "import scipy" 2>/dev/null; then PYTHON=/usr/bin/python3; else PYTHON=python3; fi
fi
C_OUT=$("$BUILD/bench_strain")
echo "$C_OUT"
for t in 1 2; do
    P_OUT=$(OMP_NUM_THREADS=$t OPENBLAS_NUM_THREADS=$t "$PYTHON" bench/strain_numpy.py)
    echo "numpy (threads $t):"; echo "$P_OUT"
    for kind in single cumulative; do
        c=$(echo "$C_OUT" | awk -v k=$kind -v t=$t '$1==k { for (i=1;i<NF;i++) if ($i=="threads" && $(i+1)==t) for (j=1;j<NF;j++) if ($j=="seconds") print $(j+1) }')
        p=$(echo "$P_OUT" | awk -v k=$kind '$1==k { for (j=1;j<NF;j++) if ($j=="seconds") print $(j+1) }')
        echo "$kind threads $t: C $c s, numpy $p s, ratio $(echo "$p $c" | awk '{ printf "%.1f", $1 / $2 }')x"
    done
done
