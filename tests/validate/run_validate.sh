#!/bin/sh
# Long physics validations of cdem-c (make validate; not part of make test). Each check
# prints one OK/FAIL line; the script ends with "validate: N passed, N failed" and exits
# non-zero when any failed. Usage: sh tests/validate/run_validate.sh [BUILD]
#  1. the default model (paper Fig. 7A, planar normal fault, 30 deg): full run, 56 / 282
#     increments, the hanging-wall block moved by the net displacement along the dip;
#  2. a planar reverse fault (50 deg, shorter run);
#  3. a planar normal fault with inversion at 50 %: net displacement zero at the end.
BUILD=${1:-build}
RUN="$BUILD/cdem-run"
CHECK="/usr/bin/python3 tests/validate/check_planar.py"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
passed=0; failed=0

check() { # name, then the command
    name=$1; shift
    if "$@" >"$TMP/$name.log" 2>&1; then
        passed=$((passed + 1)); echo "validate: $name: OK $(tail -n 1 "$TMP/$name.log")"
    else
        failed=$((failed + 1)); echo "validate: $name: FAILED"; tail -n 20 "$TMP/$name.log"
    fi
}

[ -x "$RUN" ] || { echo "validate: $RUN not built"; exit 1; }

check default-run "$RUN" -q -o "$TMP/default.h5"
check default-kinematics $CHECK "$TMP/default.h5" --equil 56 --total 282 --dip 30 --sense normal

check reverse-run "$RUN" -q -o "$TMP/reverse.h5" -s boundary.fault_sense=reverse \
    -s boundary.fault_dip=50 -s time.runtime=1000 -s time.display_interval=10
EQ=$(/usr/bin/python3 -c "import h5py,sys; f=h5py.File('$TMP/reverse.h5','r'); g=[f['increments'][k] for k in sorted(f['increments'])]; print(max(int(x.attrs['number']) for x in g if int(x.attrs['phase'])==0), len(g)-1)" 2>/dev/null)
check reverse-kinematics $CHECK "$TMP/reverse.h5" --equil ${EQ% *} --total ${EQ#* } --dip 50 --sense reverse

check inversion-run "$RUN" -q -o "$TMP/inversion.h5" -s boundary.inversion=on \
    -s boundary.inversion_percent=50 -s time.runtime=1000 -s time.display_interval=10
EQ=$(/usr/bin/python3 -c "import h5py,sys; f=h5py.File('$TMP/inversion.h5','r'); g=[f['increments'][k] for k in sorted(f['increments'])]; print(max(int(x.attrs['number']) for x in g if int(x.attrs['phase'])==0), len(g)-1)" 2>/dev/null)
check inversion-kinematics $CHECK "$TMP/inversion.h5" --equil ${EQ% *} --total ${EQ#* } --dip 30 --sense normal --net-fraction 0

echo "validate: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
