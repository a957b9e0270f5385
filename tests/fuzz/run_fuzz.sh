#!/bin/sh
# Runs each libFuzzer harness for SECONDS, one after another, under nice -n 15 (the machine
# is shared). Usage: tests/fuzz/run_fuzz.sh BUILD SECONDS HARNESS...
# The working corpus is BUILD/corpus/<harness> (seeded from tests/fuzz/corpus/<harness>, the
# regression corpus, and kept between runs); crashing inputs go to BUILD/artifacts/<harness>/.
# A log per harness is BUILD/logs/<harness>.log; its last "#N DONE" line has the execution
# count. Exits non-zero when any harness reported a crash, leak, timeout or sanitizer error.
set -u
BUILD=${1:?usage: run_fuzz.sh BUILD SECONDS HARNESS...}
SECONDS_EACH=${2:?usage: run_fuzz.sh BUILD SECONDS HARNESS...}
shift 2
ROOT=$(pwd)
export LSAN_OPTIONS="suppressions=$ROOT/tests/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
status=0
for h in "$@"; do
    bin="$BUILD/fuzz/fuzz_$h"
    [ -x "$bin" ] || { echo "fuzz: $bin is missing (make fuzz-build)"; status=1; continue; }
    mkdir -p "$BUILD/corpus/$h" "$BUILD/artifacts/$h" "$BUILD/logs"
    cp -n "tests/fuzz/corpus/$h/"* "$BUILD/corpus/$h/" 2>/dev/null
    dict=""
    [ -f "tests/fuzz/$h.dict" ] && dict="-dict=tests/fuzz/$h.dict"
    log="$BUILD/logs/$h.log"
    echo "fuzz: $h for ${SECONDS_EACH} s (log $log)"
    # fuzz_h5: HDF5 loses memory on corrupt headers (fuzz_h5.c); telling those leaks apart
    # needs the slow unwinder (7x fewer executions), so leaks are checked in a second pass
    # over the whole corpus instead of during fuzzing.
    extra=""
    asan="${ASAN_OPTIONS:-}"
    if [ "$h" = h5 ]; then
        extra="-detect_leaks=0"
        asan="fast_unwind_on_malloc=1:detect_leaks=0"
    fi
    # shellcheck disable=SC2086
    ASAN_OPTIONS="$asan" nice -n 15 "$bin" -max_total_time="$SECONDS_EACH" -timeout=20 \
        -rss_limit_mb=2048 -max_len=400000 -print_final_stats=1 \
        -artifact_prefix="$BUILD/artifacts/$h/" $dict $extra "$BUILD/corpus/$h" >"$log" 2>&1
    rc=$?
    if [ "$rc" -eq 0 ] && [ "$h" = h5 ]; then
        echo "fuzz: $h: leak check over the corpus (log $log.leaks)"
        nice -n 15 "$bin" -runs=0 -timeout=20 -rss_limit_mb=2048 -max_len=400000 \
            -artifact_prefix="$BUILD/artifacts/$h/" "$BUILD/corpus/$h" >"$log.leaks" 2>&1
        rc=$?
    fi
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    if [ "$rc" -ne 0 ]; then
        echo "fuzz: $h FAILED (exit $rc) after ${execs:-?} executions; see $log and $BUILD/artifacts/$h/"
        status=1
    else
        echo "fuzz: $h ok, ${execs:-?} executions, corpus $(ls "$BUILD/corpus/$h" | wc -l) inputs"
    fi
done
exit $status
