#!/bin/sh
# Runs every test binary in BUILD/tests that has its source tests/NAME.c, from the repository
# root, and prints each cmocka summary followed by one closing line "tests: N passed, N
# failed" over all binaries. (A binary left in a build folder by a test since removed is
# skipped and named: it counted 4 tests of a deleted file in a long-lived build.)
# Exits non-zero when any test fails or a binary crashes.
BUILD=${1:-build}
export CDEM_TEST_DATA="$(pwd)/tests/data"
export CDEM_BUILD="$(pwd)/$BUILD"
# Regression corpus of the fuzz harnesses, replayed by test_fuzz_corpus (tests/fuzz/).
export CDEM_FUZZ_CORPUS="$(pwd)/tests/fuzz/corpus"
# Third-party leaks (fontconfig) in programs the tests run under make asan.
export LSAN_OPTIONS="suppressions=$(pwd)/tests/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
TMPROOT=$(mktemp -d)
export CDEM_TEST_TMP="$TMPROOT"
trap 'rm -rf "$TMPROOT"' EXIT
passed=0; failed=0; crashed=""
for t in "$BUILD"/tests/test_*; do
    [ -x "$t" ] || continue
    case $t in *.d | *.o) continue ;; esac
    if [ ! -f "tests/$(basename "$t").c" ]; then
        echo "skipped $(basename "$t"): no tests/$(basename "$t").c (left by a removed test)"
        continue
    fi
    out="$TMPROOT/$(basename "$t").log"
    "$t" >"$out" 2>&1
    rc=$?
    cat "$out"
    p=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$out" | tail -n 1)
    f=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$out" | tail -n 1)
    passed=$((passed + ${p:-0}))
    failed=$((failed + ${f:-0}))
    if [ "$rc" -ne 0 ] && [ -z "$f" ]; then
        crashed="$crashed $(basename "$t")"
        failed=$((failed + 1))
    fi
done
[ -n "$crashed" ] && echo "crashed or exited non-zero:$crashed"
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
