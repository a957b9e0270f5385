#!/bin/sh
# make validate, item 5b: cdem-strain calibrate's whole loop on the calibration set-up
# (examples/calibration/biaxial.ini) at reduced size (400 / 1100 s: axial strain ~0.1;
# 0, 10, 20 MPa; two seeds per series), with real searches:
#   1. a reachable target (phi 30 +- 2 deg, C 4.5 +- 1 MPa at this size) is found within
#      8 series, its fresh-seed check within the tolerances, a [material] block written;
#      the calibration is killed (SIGTERM) while its second series runs and started again:
#      it resumes (the killed runs continued with cdem-run --resume, which gives the
#      uninterrupted run's file: test_crash, item 8; the finished ones read), and a third
#      invocation runs nothing and gives the same material (the search keeps no state: the
#      same runs give the same steps);
#   2. a cohesion the model cannot reach at this friction angle (1 MPa at phi 34 deg: the
#      damping's share is about 3 MPa at this size) is refused with the range found.
# Usage: sh tests/validate/check_calibrate.sh BUILD SCRATCH
set -u
BUILD=$1
TMP=$2
STRAIN="$(cd "$BUILD" && pwd)/cdem-strain"
MODEL="$(pwd)/examples/calibration/biaxial.ini"
REDUCED="--pressures 0,10,20 --seeds 2 --jobs 2 -s time.equilibration=400 -s time.runtime=1100"
mkdir -p "$TMP/calibrate" && cd "$TMP/calibrate" || exit 1
fail() { echo "check_calibrate: $*"; exit 1; }

# 1. found, killed in the middle and resumed
# shellcheck disable=SC2086
"$STRAIN" calibrate "$MODEL" --phi 30 --phi-tol 2 --cohesion 4.5 --cohesion-tol 1 $REDUCED \
    --work found > first.out 2>&1 &
pid=$!
i=0
until grep -q "^series 2:" found/calibration.txt 2>/dev/null && ls found/*seed1_*MPa.h5.lock \
        > /dev/null 2>&1; do
    i=$((i + 1))
    [ $i -gt 1200 ] && fail "no second series after 10 minutes"
    kill -0 $pid 2>/dev/null || break # found in one series: nothing to interrupt
    sleep 0.5
done
if kill -0 $pid 2>/dev/null; then
    sleep 2
    kill -TERM $pid
    wait $pid
    echo "killed while running: $(grep -c '^  running' first.out) runs started"
else
    wait $pid
fi
# shellcheck disable=SC2086
"$STRAIN" calibrate "$MODEL" --phi 30 --phi-tol 2 --cohesion 4.5 --cohesion-tol 1 $REDUCED \
    --work found > second.out 2>&1
rc=$?
cat second.out
[ $rc -eq 0 ] || fail "the resumed calibration exited $rc"
grep -q "^series 1: .*(6 runs, none run now)" second.out || fail "series 1 was run again"
grep -q "^found in " second.out || fail "no material found"
grep -q "fresh-seed check: within the tolerances" second.out || fail "fresh-seed check"
grep -q "^element_friction = " found/material.ini || fail "no [material] block"
n=$(grep -c "^series [0-9]*: mu = .*run now)" second.out)
[ "$n" -le 8 ] || fail "$n series (at most 8)"
grep "^element_" found/material.ini > found.material
# a third time: nothing runs, the same material (the search repeats its steps from the runs)
# shellcheck disable=SC2086
"$STRAIN" calibrate "$MODEL" --phi 30 --phi-tol 2 --cohesion 4.5 --cohesion-tol 1 $REDUCED \
    --work found > third.out 2>&1 || fail "the third calibration failed"
grep -q "^  running\|^  resuming" third.out && fail "the third calibration ran something"
grep "^element_" found/material.ini | cmp -s - found.material || fail "another material"

# 2. refused with the range found
# shellcheck disable=SC2086
"$STRAIN" calibrate "$MODEL" --phi 34 --cohesion 1 $REDUCED --check-seeds 0 --work refused \
    > refused.out 2>&1
rc=$?
cat refused.out
[ $rc -eq 1 ] || fail "the unreachable target exited $rc, not 1"
grep -q "^refused: the target cohesion 1 MPa is out of reach" refused.out || fail "no refusal"
grep -q "Reachable cohesion found (series with phi on its target" refused.out ||
    fail "no reachable range"
n=$(grep -c "^series [0-9]*: mu = .*run now)" refused.out)
[ "$n" -le 8 ] || fail "$n series (at most 8)"
echo "found: $(tr '\n' ' ' < found.material)in $(grep -c '^series [0-9]*: mu = .*run now)' \
    second.out) series after a kill; refused: $(grep -o 'Reachable cohesion found (series with phi on its target (within 2 tolerances)): [0-9.]* to [0-9.]* MPa' \
    refused.out)"
