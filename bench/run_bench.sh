#!/bin/sh
# make bench: the performance report of docs/performance.md, in one self-explanatory output.
#   0. The machine now: 2-thread speed-up of a compute-bound loop and of a streaming triad
#      at 6, 24 and 240 MB (bench/bench_machine.c), the ceiling for the solver's own.
#   1. Solver scaling: ns per element-step at ~2k, ~9k, ~35k and ~125k elements (the 100 x
#      7.5 half-radii assembly), 1 and 2 threads interleaved in one process, medians of REPS,
#      wall clock and CPU time, 2-thread speed-up (bench/bench_scale.c, "scale"); beside it
#      the machine's ceiling for that speed-up at that size and moment ("twins": two models
#      stepped at once by one thread each in one process, against one alone) and the share of
#      it the 2-thread run reached (bench/bench_scale.c, "twins").
#   2. Long run: element-steps/s in each tenth of the default model's full schedule, first
#      vs last tenth (bench/bench_scale.c, "full").
#   3. Against LAMMPS on the same run (bench/lammps_bench.sh; installs Debian's lammps); the
#      1-core ratio also in ROUNDS rounds with the order swapped, and their median.
#   4. Analysis path: the default run's HDF5 file (size per element-increment against the
#      original program's 10.1 MB), reading every increment (bench/bench_io.c), strain and
#      rendering with cdem-strain on that file, the synthetic strain benchmark beside its
#      numpy/scipy baseline (bench/bench_strain.sh) and the renderer (bench/bench_render.c).
#   5. Threads on a busy machine (bench/contended.sh): 1 and 2 threads, idle and with one
#      CPU-bound competitor process that the script starts and stops, with cdem-run's own
#      wait policy and with libgomp's default, in the same run.
#   6. Scale: every phase per element at ~10^4, ~2.5 x 10^5 and ~10^6 elements (build,
#      BIG_STEPS time steps on 1 and 2 threads, writing three increments, cdem-strain compute
#      and render of the total strain) and the peak memory per element (bench/bench_big.c);
#      about 4 minutes.
# Usage: sh bench/run_bench.sh [BUILD]   (make bench; about 10 minutes on an idle 2-core box)
# Environment:
#   SIZES="10:5:0 10:5:1 40:5:1 100:7.5:1"  width:height:half_radii of the scaling table
#   LARGE=1     adds 200 x 7.5 half radii (~250,000 elements; ~1.5 more minutes)
#   REPS=3      timed runs per size and thread count (medians)
#   ELSTEPS=2e7 element-steps per timed run;  SETTLE=3000 untimed settling steps
#   PARTS="machine scale full lammps analysis contended big"  the parts to run
#   BIG_SIZES="24:10:1 100:7.5:0.356 100:7.5:0.178" width:height:radius_scale of part 6;
#   BIG_STEPS=1000
#   WORK=/tmp/cdem_bench  scratch directory (the default run's file is kept there)
# OMP_WAIT_POLICY is left as the caller has it. cdem-run and cdem-strain, when it is unset,
# choose passive themselves (common/threads.h; part 5 measures why); the benchmark programs
# built here (bench_scale, bench_io) do not, so with it unset parts 1-2 measure libgomp's
# default (an idle thread spins for a while, then sleeps), which on an idle machine gives the
# same 2-thread times within the noise (part 5).
# Every figure is printed with the load average beside it: on a loaded machine the
# wall-clock figures measure the other jobs too; the CPU-time figures are steadier but also
# inflated (shared caches and cores).
BUILD=${1:-build}
SIZES=${SIZES:-"10:5:0 10:5:1 40:5:1 100:7.5:1"}
[ "${LARGE:-0}" = 1 ] && SIZES="$SIZES 200:7.5:1"
REPS=${REPS:-3}
ELSTEPS=${ELSTEPS:-2e7}
SETTLE=${SETTLE:-3000}
PARTS=${PARTS:-"machine scale full lammps analysis contended big"}
BIG_SIZES=${BIG_SIZES:-"24:10:1 100:7.5:0.356 100:7.5:0.178"}
BIG_STEPS=${BIG_STEPS:-1000}
WORK=${WORK:-/tmp/cdem_bench}
PKGS="hdf5 gsl"
CFLAGS="-O2 -g -std=c17 -Wall -Wextra -Werror -fopenmp -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -Icommon $(for d in solver/*/; do printf " -I%s" "${d%/}"; done)"
set -e
mkdir -p "$WORK"
cc $CFLAGS $(pkg-config --cflags $PKGS) -o "$BUILD/bench_scale" bench/bench_scale.c \
    "$BUILD/libcdemsolver.a" "$BUILD/libcdem.a" $(pkg-config --libs $PKGS) -lm
cc $CFLAGS $(pkg-config --cflags $PKGS) -o "$BUILD/bench_io" bench/bench_io.c \
    "$BUILD/libcdem.a" $(pkg-config --libs $PKGS) -lz -lm
cc $CFLAGS -o "$BUILD/bench_machine" bench/bench_machine.c -lm
cc $CFLAGS $(pkg-config --cflags $PKGS zlib) -o "$BUILD/bench_big" bench/bench_big.c \
    "$BUILD/libcdemsolver.a" "$BUILD/libcdem.a" $(pkg-config --libs $PKGS zlib) -lm

# the CPU model, printed with every figure (docs/performance.md keeps a table per CPU family)
CPU=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')
CDEM_BENCH_CPU=${CPU:-unknown CPU}
CPU=$CDEM_BENCH_CPU
export CDEM_BENCH_CPU
# appends the CPU model to every non-empty line of its input (the piped parts' figures)
tag_cpu() { awk -v c="$CPU" 'NF {print $0 "  [" c "]"; next} {print}'; }
has() { case " $PARTS " in *" $1 "*) return 0 ;; esac; return 1; }
load() { cut -d' ' -f1-3 /proc/loadavg; }
now() { date +%s.%N; }
# median of the numbers on stdin
median() { sort -g | awk '{a[NR]=$1} END {if (NR == 0) print "nan"; else if (NR % 2) print a[(NR+1)/2]; else print (a[NR/2]+a[NR/2+1])/2}'; }
# value of field NAME (the word after NAME) of the lines matching PATTERN in FILE
field() { awk -v pat="$2" -v name="$1" '$0 ~ pat {for (i = 1; i < NF; i++) if ($i == name) print $(i+1)}' "$3"; }

echo "cdem bench: $(date -u '+%Y-%m-%d %H:%M UTC'), commit $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores," \
    "$(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo); load average $(load)"
echo "OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-(unset: libgomp default, spin then sleep)}; compiler flags -O2 (the project's)"

if has machine; then
    echo
    echo "== 0. The machine now (bench/bench_machine.c): what 2 threads can gain over 1, compute-bound and streaming"
    "$BUILD/bench_machine" | awk '
        / compute / {printf "   compute (square roots, divisions; no memory): 2 threads %.2fx 1 thread\n", $8}
        / triad /   {printf "   triad over %4s MB: %5.1f GB/s on 1 thread, %5.1f on 2: %.2fx\n", $4, $6, $8, $10}' | tag_cpu
    echo "   (on a shared virtual machine the streaming ratios vary from run to run; the solver's 2-thread speed-up"
    echo "   at ~35,000 elements and above follows the 6 and 24 MB ones)"
fi

if has scale; then
    echo
    echo "== 1. Solver scaling (deformation of the default planar normal fault after $SETTLE settling steps;"
    echo "      N = all elements incl. walls; median of $REPS runs of ~$ELSTEPS element-steps; 1 and 2 threads interleaved)"
    printf '%-16s %8s %8s %6s | %9s %9s %9s | %9s %9s %9s | %7s %7s %8s | %-11s | %s\n' size N pairs builds \
        "ns/el 1t" "cpu 1t" "ns/cont" "ns/el 2t" "cpu 2t" "el-st/s" "2t/1t" "twins" "2t/twins" "load during" "CPU"
    for size in $SIZES; do
        w=$(echo "$size" | cut -d: -f1)
        h=$(echo "$size" | cut -d: -f2)
        hr=$(echo "$size" | cut -d: -f3)
        out="$WORK/scale_${w}_${h}_${hr}.out"
        "$BUILD/bench_scale" scale "$w" "$h" "$hr" "$SETTLE" "$ELSTEPS" "$REPS" "1 2" >"$out"
        n=$(field N "threads 1 " "$out" | tail -n 1)
        np=$(field pairs "threads 1 " "$out" | tail -n 1)
        nb=$(field builds "threads 1 " "$out" | median)
        w1=$(field ns_per_el_step "threads 1 " "$out" | median)
        c1=$(field cpu_ns_per_el_step "threads 1 " "$out" | median)
        k1=$(field ns_per_contact_step "threads 1 " "$out" | median)
        w2=$(field ns_per_el_step "threads 2 " "$out" | median)
        c2=$(field cpu_ns_per_el_step "threads 2 " "$out" | median)
        r2=$(field el_steps_per_s "threads 2 " "$out" | median)
        # speed-up per repetition (1t and 2t of the same repetition are adjacent in time)
        sp=$(awk '/threads 1 / {for (i=1;i<NF;i++) if ($i=="seconds") a[$3]=$(i+1)}
                  /threads 2 / {for (i=1;i<NF;i++) if ($i=="seconds") if (a[$3] > 0) print a[$3]/$(i+1)}' "$out" | median)
        # the ceiling: two independent models stepped at once, one thread each, in one
        # process (no sharing, no synchronisation), against one alone around them; and in the
        # same repetition the 2-thread run, as a share of that ceiling (the VM's vCPUs change
        # speed independently: the two are measured adjacent, repetition by repetition)
        "$BUILD/bench_scale" twins "$w" "$h" "$hr" "$SETTLE" "$ELSTEPS" "$REPS" >"$out.twins"
        cp=$(field ceiling "BENCH_TWINS" "$out.twins" | median)
        ef=$(field efficiency "BENCH_TWINS" "$out.twins" | median)
        ld=$(field load "" "$out" | sort -g | awk 'NR==1 {lo=$1} {hi=$1} END {print lo "-" hi}')
        printf '%-16s %8s %8s %6s | %9.1f %9.1f %9.1f | %9.1f %9.1f %9.3g | %6.2fx %6.2fx %8.2f | %-11s | %s\n' \
            "${w}x${h} half=$hr" "$n" "$np" "$nb" "$w1" "$c1" "$k1" "$w2" "$c2" "$r2" "$sp" "$cp" "$ef" "$ld" "$CPU"
    done
    echo "   ns/el = wall-clock ns per element-step (linear scaling = the same figure at every size);"
    echo "   cpu = process CPU ns per element-step (2t: both threads, so cpu 2t ~ cpu 1t when the threads do no extra work);"
    echo "   ns/cont = 1-thread wall ns per touching pair per step; builds = list rebuilds per timed run; 2t/1t = speed-up"
    echo "   (median of the per-repetition ratios); twins = two models of this size stepped at once in one process, one"
    echo "   thread each, their joint rate over one alone (median): what the 2 cores give work that shares nothing, now,"
    echo "   the ceiling of 2t/1t; 2t/twins = the 2-thread speed-up over that ceiling in the same repetition (median;"
    echo "   1 = the threads lose nothing to sharing one model); raw lines in $WORK/scale_*.out(.twins)"
fi

if has full; then
    echo
    echo "== 2. Long run: the default model's whole schedule on 1 thread (bench_scale full 10 5 0), element-steps/s per tenth"
    out="$WORK/full.out"
    OMP_NUM_THREADS=1 "$BUILD/bench_scale" full 10 5 0 >"$out"
    awk -v cpu="$CPU" '/^BENCH_FULL/ {for (i=1;i<NF;i++) {if ($i=="tenth") t=$(i+1); if ($i=="phase") ph=$(i+1);
         if ($i=="el_steps_per_s") r=$(i+1); if ($i=="cpu_el_steps_per_s") c=$(i+1); if ($i=="builds") b=$(i+1); if ($i=="N") n=$(i+1)}
         printf "   tenth %2d  %-13s N %5d  builds %4d  %.3g el-steps/s (per CPU-second %.3g) on %s\n", t, ph, n, b, r, c, cpu}' "$out"
    f=$(field el_steps_per_s "tenth 1 " "$out")
    l=$(field el_steps_per_s "tenth 10 " "$out")
    fc=$(field cpu_el_steps_per_s "tenth 1 " "$out")
    lc=$(field cpu_el_steps_per_s "tenth 10 " "$out")
    # the first tenth wholly in deformation (the equilibration is ~20 % of the default run)
    d=$(awk '/^BENCH_FULL/ && / phase deformation / {for (i=1;i<NF;i++) if ($i=="tenth") {print $(i+1); exit}}' "$out")
    df=$(field cpu_el_steps_per_s "tenth $d " "$out")
    echo "   last tenth / first tenth: $(awk -v a="$f" -v b="$l" 'BEGIN {printf "%.2f", b/a}') by the wall clock," \
        "$(awk -v a="$fc" -v b="$lc" 'BEGIN {printf "%.2f", b/a}') per CPU-second (1.00 = no degradation; the first tenth is"
    echo "   equilibration, with more list rebuilds); last tenth / first deformation tenth ($d):" \
        "$(awk -v a="$df" -v b="$lc" 'BEGIN {printf "%.2f", b/a}') per CPU-second; load average now $(load); $CPU"
fi

if has lammps; then
    echo
    echo "== 3. Against LAMMPS on the same run (bench/lammps_bench.sh)"
    sh bench/lammps_bench.sh "$BUILD" || echo "   lammps_bench failed (status $?)"
fi

if has analysis; then
    echo
    echo "== 4. Analysis path"
    h5="$WORK/default.h5"
    t0=$(now)
    OMP_NUM_THREADS=1 "$BUILD/cdem-run" -q --force -o "$h5"  # the benchmark's own scratch file
    t1=$(now)
    echo "   default run (cdem-run, 1 thread, writes every increment): $(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.1f", b-a}') s, load $(load)  [$CPU]"
    "$BUILD/bench_io" "$h5" 3 >"$WORK/io.out"
    awk '{for (i=1;i<NF;i++) v[$i]=$(i+1)}
         END {printf "   file: %.2f MB for %d increments x %d elements = %.1f bytes per element-increment;" \
                     " the original program: 10.1 MB for its default run (ratio %.2f)\n", v["file_MB"], v["increments"], v["mean_elements"], v["bytes_per_element_increment"], v["file_MB"]/10.1;
              printf "   reading (cdem_h5_reader_load_increment, every increment, median of 3): %.2f ms per increment" \
                     " (%.2f ms CPU), %.0f ns per element\n", v["load_ms_per_increment"], v["cpu_ms_per_increment"], v["ns_per_element"]}' "$WORK/io.out" | tag_cpu
    for t in 1 2; do
        t0=$(now)
        OMP_NUM_THREADS=$t "$BUILD/cdem-strain" compute "$h5" --increment last --quantity total-max-shear \
            -o "$WORK/strain.csv" >/dev/null
        t1=$(now)
        OMP_NUM_THREADS=$t "$BUILD/cdem-strain" compute "$h5" --increment all --quantity incr-max-shear \
            --format h5 -o "$WORK/strain_all.h5" >/dev/null
        t2=$(now)
        echo "   cdem-strain compute, $t thread(s): total max. shear of the last increment (whole process incl. reading," \
            "CSV) $(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.2f", b-a}') s; incremental max. shear of all" \
            "increments (HDF5 out) $(awk -v a="$t1" -v b="$t2" 'BEGIN {printf "%.2f", b-a}') s  [$CPU]"
    done
    t0=$(now)
    OMP_NUM_THREADS=1 "$BUILD/cdem-strain" render "$h5" --increment last -o "$WORK/last.png" >/dev/null
    t1=$(now)
    OMP_NUM_THREADS=1 "$BUILD/cdem-strain" render "$h5" --increment last --color total-max-shear \
        -o "$WORK/last_shear.png" >/dev/null
    t2=$(now)
    echo "   cdem-strain render, last increment to PNG (whole process): layer colours" \
        "$(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.2f", b-a}') s, coloured by total max. shear" \
        "$(awk -v a="$t1" -v b="$t2" 'BEGIN {printf "%.2f", b-a}') s; load $(load)  [$CPU]"
    echo "   -- synthetic strain benchmark beside the numpy/scipy baseline (bench/bench_strain.sh):"
    sh bench/bench_strain.sh "$BUILD" | sed 's/^/   /' | tag_cpu
    echo "   -- renderer on synthetic states (bench/bench_render.c, best of 3 draws):"
    make -s "$BUILD/libcdemanalysis.a" "$BUILD/libcdem.a"
    cc -O2 -std=c17 -D_DEFAULT_SOURCE -Icommon -Ianalysis/measure -Ianalysis/input -Ianalysis/draw $(pkg-config --cflags cairo) \
        bench/bench_render.c "$BUILD/libcdemanalysis.a" "$BUILD/libcdem.a" \
        $(pkg-config --libs cairo) -lgif -lm -fopenmp -o "$BUILD/bench_render"
    "$BUILD/bench_render" "$WORK" render | sed 's/^/   /' | tag_cpu
    echo "   load average now $(load)"
fi

if has contended; then
    echo
    echo "== 5. Threads on a busy machine (bench/contended.sh): cdem-run as it comes (passive wait policy,"
    echo "      common/threads.h, and the thread governor, solver/run/governor.h), without the governor"
    echo "      (cdem-fixed), and with libgomp's default spin, idle and with one CPU-bound competitor"
    WAITS="cdem cdem-fixed libgomp" sh bench/contended.sh "$BUILD" | tag_cpu
fi

if has big; then
    echo
    echo "== 6. Scale: every phase per element from ~10^4 to ~10^6 elements (bench/bench_big.c; $BIG_STEPS steps,"
    echo "      half in equilibration, half deforming the planar fault, blocks of 1 and 2 threads alternating)"
    printf "   %9s %9s %9s %9s %10s %10s %10s %10s %10s %9s\n" elements build_us \
        ns/el-st1t ns/el-st2t write_us B/el-inc compute_us render_us bytes/el compute_B
    for spec in $BIG_SIZES; do
        w=${spec%%:*}; rest=${spec#*:}; h=${rest%%:*}; rs=${rest#*:}
        line=$("$BUILD/bench_big" "$w" "$h" "$rs" "$BIG_STEPS" "$WORK" "$BUILD/cdem-strain") || {
            echo "   $spec: bench_big failed"; continue; }
        echo "$line" | awk '{for (i = 2; i < NF; i += 2) v[$i] = $(i + 1);
            printf "   %9d %9.2f %10.1f %10.1f %10.2f %10.1f %10.2f %10.2f %10.0f %9.0f\n",
            v["N"], v["build_us_per_el"], v["ns_per_el_step_1t"], v["ns_per_el_step_2t"],
            v["write_us_per_el_incr"], v["file_bytes_per_el_incr"], v["compute_us_per_el"],
            v["render_us_per_el"], v["rss_bytes_per_el"], v["compute_rss_bytes_per_el"]}'
    done
    echo "   (per element: build, writing an increment, compute and render in microseconds; a time step in"
    echo "   nanoseconds; bytes: the file per element and increment, and the peak resident memory of the"
    echo "   solver process and of cdem-strain compute; load average now $(load))"
fi
