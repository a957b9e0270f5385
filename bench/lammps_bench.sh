#!/bin/sh
# lammps_bench.sh -- side-by-side benchmark of cdem against LAMMPS on the same run
# (called by bench/run_bench.sh, i.e. `make bench`; docs/performance.md, "Against LAMMPS,
# same run", records the figures).
#
# For each size: build/export_lammps (bench/export_lammps.c) builds cdem's assembly,
# equilibrates it (untimed), zeroes the shear springs, writes the packing and constants for
# LAMMPS, runs NPHYS static steps and then REPS timed runs of NTIME steps on 1 and 2 OpenMP
# threads. LAMMPS (bench/lammps_bench.in) reads the same packing and constants and runs the
# same NPHYS + REPS x NTIME steps on 1 rank, on 2 MPI ranks and on 2 OpenMP threads (-sf omp).
#   Physics check: after NPHYS steps, kinetic energy of the free elements and mean overlap of
#   the touching pairs (bench/lammps_overlap.py on both dumps) must agree within KE_TOL and
#   OV_TOL (relative); printed as PASS/FAIL.
#   Timing: element-steps/s = N (all elements, walls included) x NTIME / time of one timed
#   run (cdem: clock around the step loop; LAMMPS: its "Loop time"), median of REPS; the
#   ratio cdem/LAMMPS; peak memory (/usr/bin/time -v "Maximum resident set size").
#   Rounds: the 1-core ratio is measured again in ROUNDS - 1 further rounds of the cdem run and
#   the LAMMPS 1-rank run, the order swapped every round, and printed per round with its
#   median: this VM runs the two programs at different speeds from one minute to the next
#   (2026-11-27: 2.69x and 3.01x at 2,395 elements in two make benches of the same programs,
#   4.33-4.44x the day before; docs/performance.md).
# Usage: sh bench/lammps_bench.sh [BUILD]
#   env: SIZES="10:0 10:1 40:1" (width_units:half_radii[:height_units, default 5]: ~2,500,
#        ~9,100 and ~35,000 elements; 40:1 is most of the 3-4 minutes, mostly cdem's
#        equilibration; add 100:1:7.5 for ~125,000 elements, about 6 more minutes), REPS=3,
#        ROUNDS=3 (1: the first pair of runs only; each further round repeats cdem's
#        equilibration, about a minute at 40:1),
#        NPHYS=2000, WORK=/tmp/cdem_lammps_bench, ELSTEPS=2e7 (element-steps per timed
#        run), KE_TOL=0.02, OV_TOL=0.01
# Installs Debian's lammps (and time) with apt-get when missing (needs root).
BUILD=${1:-build}
SIZES=${SIZES:-"10:0 10:1 40:1"}
REPS=${REPS:-3}
ROUNDS=${ROUNDS:-3}
case $ROUNDS in
'' | *[!0-9]* | 0)
    echo "lammps_bench: ROUNDS=$ROUNDS: must be a whole number >= 1" >&2
    exit 2
    ;;
esac
NPHYS=${NPHYS:-2000}
WORK=${WORK:-/tmp/cdem_lammps_bench}
ELSTEPS=${ELSTEPS:-2e7}
KE_TOL=${KE_TOL:-0.02}
OV_TOL=${OV_TOL:-0.01}
PY=/usr/bin/python3
set -e
# OMP_WAIT_POLICY: as the caller has it (run_bench.sh explains why it is not forced)

if [ ! -x /usr/bin/lmp ] || [ ! -x /usr/bin/time ]; then
    echo "lammps_bench: installing lammps/time with apt-get"
    apt-get install -y lammps time >"$WORK.apt.log" 2>&1 || {
        echo "lammps_bench: apt-get install lammps time failed (see $WORK.apt.log); skipped"
        exit 0
    }
fi
MPIRUN="mpirun -np 2 --bind-to core"
[ "$(id -u)" = 0 ] && MPIRUN="mpirun --allow-run-as-root -np 2 --bind-to core"

CFLAGS="-O2 -g -std=c17 -Wall -Wextra -Werror -fopenmp -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -Icommon $(for d in solver/*/; do printf " -I%s" "${d%/}"; done)"
cc $CFLAGS $(pkg-config --cflags hdf5 gsl) -o "$BUILD/export_lammps" bench/export_lammps.c \
    "$BUILD/libcdemsolver.a" "$BUILD/libcdem.a" $(pkg-config --libs hdf5 gsl) -lm

# median of the numbers on stdin
median() { sort -g | awk '{a[NR]=$1} END {if (NR % 2) print a[(NR+1)/2]; else print (a[NR/2]+a[NR/2+1])/2}'; }
# peak RSS in MB from a /usr/bin/time -v output file
peak_mb() { awk -F: '/Maximum resident set size/ {printf "%.0f", $2/1024}' "$1"; }
relerr() { awk -v a="$1" -v b="$2" 'BEGIN {d=a-b; if (d<0) d=-d; m=(b<0?-b:b); print (m>0? d/m : d)}'; }

echo "lammps_bench: $(lmp -h | grep -m1 '^Large-scale' || true) $(lmp -h | grep -m1 'LAMMPS (' || true)"
# the CPU model, printed with every figure (run_bench.sh passes its own)
CPU=${CDEM_BENCH_CPU:-$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')}
echo "lammps_bench: machine: $CPU, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
failed=""
for size in $SIZES; do
    width=$(echo "$size" | cut -d: -f1)
    half=$(echo "$size" | cut -d: -f2)
    height=$(echo "$size:5" | cut -d: -f3)
    dir="$WORK/w${width}_h${half}_y${height}"
    mkdir -p "$dir"
    # N is known only after the assembly is built: estimate the step count from the default
    # element count (2,500 at 10 x 5; x4 for half radii; x width/10)
    n_est=$(awk -v w="$width" -v h="$half" -v y="$height" 'BEGIN {print 2500 * w / 10 * y / 5 * (h ? 4 : 1)}')
    ntime=$(awk -v e="$ELSTEPS" -v n="$n_est" 'BEGIN {s = int(e / n); print (s < 50 ? 50 : s)}')
    echo "== size ${width} x ${height} units, half_radii ${half}: ${NPHYS} physics steps, ${REPS} x ${ntime} timed steps"

    OMP_NUM_THREADS=2 /usr/bin/time -v -o "$dir/cdem.time" "$BUILD/export_lammps" "$dir" \
        "$width" "$half" "$NPHYS" "$ntime" "$REPS" "" "$height" >"$dir/cdem.out"
    OMP_NUM_THREADS=1 /usr/bin/time -v -o "$dir/lmp1.time" lmp -in bench/lammps_bench.in \
        -var dir "$dir" -var nphys "$NPHYS" -var ntime "$ntime" -var reps "$REPS" \
        -log "$dir/lmp1.log" -screen none
    OMP_NUM_THREADS=1 /usr/bin/time -v -o "$dir/lmp2.time" $MPIRUN lmp -in bench/lammps_bench.in \
        -var dir "$dir" -var nphys "$NPHYS" -var ntime "$ntime" -var reps "$REPS" \
        -log "$dir/lmp2.log" -screen none
    # the OPENMP package's styles on 2 threads (gran/hooke/history/omp, ...), where this
    # LAMMPS has them (Debian 12's lammps 20210929 does not: "Using suffix omp without
    # OPENMP package installed"); then 2 MPI ranks is LAMMPS' 2-core figure
    omp_ok=1
    OMP_NUM_THREADS=2 /usr/bin/time -v -o "$dir/lmpomp.time" lmp -sf omp -pk omp 2 \
        -in bench/lammps_bench.in -var dir "$dir" -var nphys "$NPHYS" -var ntime "$ntime" \
        -var reps "$REPS" -log "$dir/lmpomp.log" -screen none >/dev/null 2>&1 || omp_ok=0

    n=$(awk '/^CDEM_EXPORT/ {print $3}' "$dir/cdem.out")
    nfree=$(awk '/^CDEM_EXPORT/ {print $5}' "$dir/cdem.out")
    mc=$(awk '/^CDEM_EXPORT/ {print $13}' "$dir/cdem.out")
    ml=$(awk '/^LAMMPS_PHYS/ {print $7}' "$dir/lmp1.log")
    kc=$(awk '/^CDEM_PHYS/ {print $5}' "$dir/cdem.out")
    kl=$(awk '/^LAMMPS_PHYS/ {print $5}' "$dir/lmp1.log")
    kl2=$(awk '/^LAMMPS_PHYS/ {print $5}' "$dir/lmp2.log")
    oc=$($PY bench/lammps_overlap.py "$dir/cdem_phys.dump" | awk '{print $4}')
    ol=$($PY bench/lammps_overlap.py "$dir/lammps_phys.dump" | awk '{print $4}')
    dpos=$($PY bench/lammps_overlap.py "$dir/cdem_phys.dump" "$dir/lammps_phys.dump" |
        awk '/^max_position/ {print $2}')
    ek=$(relerr "$kc" "$kl")
    eo=$(relerr "$oc" "$ol")
    em=$(relerr "$mc" "$ml")
    ok=$(awk -v a="$ek" -v b="$eo" -v c="$em" -v ta="$KE_TOL" -v tb="$OV_TOL" \
        'BEGIN {print (a <= ta && b <= tb && c <= 1e-12) ? "PASS" : "FAIL"}')
    echo "   elements: $n ($nfree free, the rest frozen walls); free mass cdem $mc kg/m, LAMMPS $ml (rel. diff $em)"
    echo "   physics after $NPHYS steps: kinetic energy cdem $kc J/m, LAMMPS $kl (2 ranks: $kl2), rel. diff $ek (tol $KE_TOL)"
    echo "   physics after $NPHYS steps: mean overlap cdem $oc m, LAMMPS $ol m, rel. diff $eo (tol $OV_TOL); largest position difference $dpos m"
    echo "   physics check: $ok"
    [ "$ok" = PASS ] || failed="$failed ${width}:${half}:${height}"

    c1=$(awk '/^CDEM_TIME threads 1/ {print $11}' "$dir/cdem.out" | median)
    c2=$(awk '/^CDEM_TIME threads 2/ {print $11}' "$dir/cdem.out" | median)
    l1=$(grep '^Loop time' "$dir/lmp1.log" | tail -n "$REPS" | awk '{print $4}' | median)
    l2m=$(grep '^Loop time' "$dir/lmp2.log" | tail -n "$REPS" | awk '{print $4}' | median)
    l2o=nan
    [ "$omp_ok" = 1 ] && l2o=$(grep '^Loop time' "$dir/lmpomp.log" | tail -n "$REPS" | awk '{print $4}' | median)
    # LAMMPS on 2 cores: the faster of 2 MPI ranks and 2 OpenMP threads
    if [ "$omp_ok" = 1 ] && awk -v a="$l2o" -v b="$l2m" 'BEGIN {exit !(a < b)}'; then
        l2=$l2o
        l2how="2 OpenMP threads"
    else
        l2=$l2m
        l2how="2 MPI ranks"
    fi
    nb=$(grep '^Neighbor list builds' "$dir/lmp1.log" | tail -n "$REPS" | awk '{s += $NF} END {print s}')
    cb=$(awk '/^CDEM_TIME threads 1/ {s += $13} END {print s}' "$dir/cdem.out")
    # CPU seconds: cdem from CLOCK_PROCESS_CPUTIME_ID; LAMMPS = Loop time x its "% CPU use"
    # (1 rank only: with 2 ranks MPI busy-waiting makes CPU time meaningless)
    u1=$(awk '/^CDEM_TIME threads 1/ {print $15}' "$dir/cdem.out" | median)
    v1=$(awk '/^Loop time/ {t = $4} /% CPU use/ && t {sub("%", "", $1); print t * $1 / 100; t = 0}' \
        "$dir/lmp1.log" | tail -n "$REPS" | median)
    rate() { awk -v n="$n" -v s="$ntime" -v t="$1" 'BEGIN {printf "%.3g", n * s / t}'; }
    ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", b / a}'; }
    echo "   timing on $CPU (median of $REPS x $ntime steps; element-steps/s counting all $n elements):"
    echo "     cdem   1 thread : $c1 s  $(rate "$c1") el-steps/s  (list builds in the $REPS runs: $cb)  [$CPU]"
    echo "     cdem   2 threads: $c2 s  $(rate "$c2") el-steps/s  [$CPU]"
    echo "     LAMMPS 1 rank   : $l1 s  $(rate "$l1") el-steps/s  (list builds in the $REPS runs: $nb)  [$CPU]"
    echo "     LAMMPS 2 ranks  : $l2m s  $(rate "$l2m") el-steps/s  [$CPU]"
    if [ "$omp_ok" = 1 ]; then
        echo "     LAMMPS 2 threads: $l2o s  $(rate "$l2o") el-steps/s  (-sf omp -pk omp 2)"
    else
        echo "     LAMMPS 2 threads: not available ($(grep -m1 ERROR "$dir/lmpomp.log" || echo 'lmp -sf omp failed'))"
    fi
    echo "     per CPU-second, 1 core: cdem $u1 s $(rate "$u1") el-steps/s, LAMMPS $v1 s $(rate "$v1") el-steps/s  [$CPU]"
    echo "     ratio cdem/LAMMPS: 1 core $(ratio "$c1" "$l1")x (per CPU-second $(ratio "$u1" "$v1")x), 2 cores $(ratio "$c2" "$l2")x (against LAMMPS' faster: $l2how)  [$CPU]"
    echo "     speed-up 1 -> 2 cores: cdem $(ratio "$c2" "$c1")x, LAMMPS $(ratio "$l2" "$l1")x  [$CPU]"
    # further rounds of the 1-core pair, the order swapped every round (see the top)
    rounds="$(ratio "$c1" "$l1")"
    r=2
    while [ "$r" -le "$ROUNDS" ]; do
        cdem_round() {
            OMP_NUM_THREADS=2 "$BUILD/export_lammps" "$dir" "$width" "$half" "$NPHYS" "$ntime" \
                "$REPS" "" "$height" >"$dir/cdem.r$r.out"
        }
        lmp_round() {
            OMP_NUM_THREADS=1 lmp -in bench/lammps_bench.in -var dir "$dir" -var nphys "$NPHYS" \
                -var ntime "$ntime" -var reps "$REPS" -log "$dir/lmp1.r$r.log" -screen none
        }
        if [ $((r % 2)) = 0 ]; then lmp_round; cdem_round; else cdem_round; lmp_round; fi
        rc1=$(awk '/^CDEM_TIME threads 1/ {print $11}' "$dir/cdem.r$r.out" | median)
        rl1=$(grep '^Loop time' "$dir/lmp1.r$r.log" | tail -n "$REPS" | awk '{print $4}' | median)
        rounds="$rounds $(ratio "$rc1" "$rl1")"
        r=$((r + 1))
    done
    echo "     ratio cdem/LAMMPS on 1 core in $ROUNDS rounds (the first above; then the order swapped each round): $rounds; median $(echo "$rounds" | tr ' ' '\n' | median)x  [$CPU]"
    echo "     load average after the size: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
    echo "   peak memory: cdem $(peak_mb "$dir/cdem.time") MB (whole process incl. equilibration)," \
        "LAMMPS 1 rank $(peak_mb "$dir/lmp1.time") MB, 2 ranks $(peak_mb "$dir/lmp2.time") MB (mpirun: largest single process)," \
        "2 threads $([ "$omp_ok" = 1 ] && peak_mb "$dir/lmpomp.time" || echo '-') MB"
    echo "   memory per element: cdem $(awk -v m="$(peak_mb "$dir/cdem.time")" -v n="$n" 'BEGIN {printf "%.2f", m * 1048576 / n / 1000}') kB," \
        "LAMMPS 1 rank $(awk -v m="$(peak_mb "$dir/lmp1.time")" -v n="$n" 'BEGIN {printf "%.2f", m * 1048576 / n / 1000}') kB (peak RSS / N, start-up included)"
done
if [ -n "$failed" ]; then
    echo "lammps_bench: physics check FAILED for$failed: the timings do not compare the same run"
    exit 1
fi
