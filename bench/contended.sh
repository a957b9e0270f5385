#!/bin/sh
# Threads on a busy machine (make bench, part "contended"; docs/performance.md, "Threads on a
# busy machine"): cdem-run's wall time on 1 and 2 threads with the machine idle and with one
# CPU-bound competitor process (a shell busy loop, started and stopped here), in one run.
# The figure of merit is busy 2t / busy 1t: threads must not make a run slower when another
# process holds a core (goal <= 1.15), while idle 1t / idle 2t keeps the speed-up.
# Usage: sh bench/contended.sh [BUILD]
# Environment:
#   WAITS="cdem"   wait settings to compare, each run in the same way:
#                  cdem      the environment as it comes (cdem-run chooses: common/threads.h,
#                            OMP_WAIT_POLICY=passive, and its thread governor, solver/run/governor.h,
#                            runs on one thread while that is faster)
#                  cdem-fixed  the same with CDEM_THREAD_GOVERNOR=off: the threads asked for,
#                            throughout (what the wait policy alone does)
#                  libgomp   GOMP_SPINCOUNT=300000, libgomp's own default
#                  passive   OMP_WAIT_POLICY=passive
#                  spin:N    GOMP_SPINCOUNT=N
#   MODEL="-s assembly.width=20 -s assembly.half_radii=on"  (16,700 elements)
#   STEPS=10000  REPS=3 (pairs; medians)  WORK=/tmp/cdem_bench  (runs of 3-6 s: shorter ones were
#                  dominated by start-up and by the governor's first probes)
BUILD=${1:-build}
WAITS=${WAITS:-cdem}
MODEL=${MODEL:-"-s assembly.width=20 -s assembly.half_radii=on"}
STEPS=${STEPS:-10000}
REPS=${REPS:-3}
WORK=${WORK:-/tmp/cdem_bench}
case $REPS in
'' | *[!0-9]* | 0)
    echo "contended.sh: REPS=$REPS: must be a whole number >= 1" >&2
    exit 2
    ;;
esac
mkdir -p "$WORK"
median() { sort -g | awk '{a[NR]=$1} END {if (NR % 2) print a[(NR+1)/2]; else print (a[NR/2]+a[NR/2+1])/2}'; }

# one timed run: wall seconds of cdem-run with the wait setting $1 on $2 threads
timed() {
    t=$2
    case $1 in
    cdem) set -- env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT -u CDEM_THREAD_GOVERNOR ;;
    cdem-fixed) set -- env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT CDEM_THREAD_GOVERNOR=off ;;
    libgomp) set -- env -u OMP_WAIT_POLICY GOMP_SPINCOUNT=300000 ;;
    passive) set -- env -u GOMP_SPINCOUNT OMP_WAIT_POLICY=passive ;;
    spin:*) set -- env -u OMP_WAIT_POLICY GOMP_SPINCOUNT="${1#spin:}" ;;
    *) echo "contended.sh: unknown wait setting $1" >&2; return 1 ;;
    esac
    s=$(date +%s.%N)
    "$@" "$BUILD/cdem-run" -q --force --no-fsync --threads "$t" --max-steps "$STEPS" $MODEL \
        -o "$WORK/contended.h5" || return 1
    e=$(date +%s.%N)
    awk -v a="$s" -v b="$e" 'BEGIN {printf "%.3f\n", b - a}'
}

# wait: REPS pairs of runs on 1 and 2 threads back to back, the order swapped every pair, so
# that the machine's drift (this VM's vCPUs change speed by up to 1.6x from minute to minute,
# docs/performance.md) falls on both counts of a pair. Prints the median 1-thread time, the
# median 2-thread time and the medians of the pairs' ratios 2t / 1t and 1t / 2t. (Three runs
# of one count and then three of the other once gave a 1-thread time 30 % apart between two
# settings that run the same code on one thread.)
measure_pairs() {
    : >"$WORK/contended.pairs"
    for r in $(seq "$REPS"); do
        if [ $((r % 2)) = 1 ]; then
            a=$(timed "$1" 1) && b=$(timed "$1" 2)
        else
            b=$(timed "$1" 2) && a=$(timed "$1" 1)
        fi || { echo "contended.sh: cdem-run failed ($1)" >&2; exit 1; }
        echo "$a $b" >>"$WORK/contended.pairs"
    done
    echo "$(cut -d' ' -f1 "$WORK/contended.pairs" | median)" \
        "$(cut -d' ' -f2 "$WORK/contended.pairs" | median)" \
        "$(awk '{print $2 / $1}' "$WORK/contended.pairs" | median)" \
        "$(awk '{print $1 / $2}' "$WORK/contended.pairs" | median)"
}

# the competitor: a CPU-bound shell loop, one core's worth
start_competitor() { sh -c 'while :; do :; done' & COMP=$!; }
stop_competitor() { kill "$COMP" 2>/dev/null; wait "$COMP" 2>/dev/null; }
trap 'stop_competitor' EXIT INT TERM

echo "   model: $MODEL, $STEPS steps ($("$BUILD/cdem-run" --summary $MODEL | awk '/free elements:/ {print $3}') free elements); $REPS pairs of 1- and 2-thread runs, medians; load before $(cut -d' ' -f1-3 /proc/loadavg)"
printf '   %-14s | %8s %8s %8s | %8s %8s %8s\n' wait "idle 1t" "idle 2t" "speed-up" "busy 1t" "busy 2t" "2t / 1t"
for w in $WAITS; do
    set -- $(measure_pairs "$w")
    [ -n "$4" ] || exit 1
    i1=$1 i2=$2 is=$4
    start_competitor
    set -- $(measure_pairs "$w")
    [ -n "$4" ] || exit 1
    b1=$1 b2=$2 bq=$3
    stop_competitor
    printf '   %-14s | %7.2fs %7.2fs %7.2fx | %7.2fs %7.2fs %7.2fx\n' "$w" "$i1" "$i2" \
        "$is" "$b1" "$b2" "$bq"
done
echo "   idle speed-up = median of the idle pairs' 1t / 2t; busy 2t / 1t = median of the busy pairs' 2t / 1t: the"
echo "   slowdown threads cause with one core busy (goal <= 1.15); the times are the medians of each count's runs"
