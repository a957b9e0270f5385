#!/bin/sh
# Makes the damaged-file corpus tests/data/damaged/ and the version-2 seeds of the fuzz corpus
# (tests/fuzz/corpus/h5/run-tiny, run-killed, synthetic): a completed cdem-run file of the
# short test model (10 x 2.5 units, 9 increments, no checkpoints), the same run SIGKILLed
# after its third increment, and the damaged variants made from them by gen_damaged.c.
# The committed files were made with this script; the moment of the kill varies, so a new
# run gives other bytes (the tests depend on the kind of damage, not on the bytes).
# Usage (from the repository root, after make): sh tests/fuzz/make_damaged.sh [BUILD]
set -eu
BUILD=${1:-build}
OUT=tests/data/damaged
SEEDS=tests/fuzz/corpus/h5
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
RUN="$BUILD/cdem-run -q --no-fsync -s assembly.height=2.5 -s time.equilibration=150
     -s time.runtime=220 -s time.display_interval=20 -s output.checkpoint_interval=0"
mkdir -p "$OUT"
# shellcheck disable=SC2086
$RUN -o "$T/complete.h5"
# killed after its third increment (increments 0..2 committed), before the end
while :; do
    rm -f "$T/killed.h5" "$T/killed.xmf" "$T/killed.h5.lock"
    # shellcheck disable=SC2086
    nice -n 19 $RUN -o "$T/killed.h5" &
    pid=$!
    n=0
    while [ "$n" -lt 3 ] && kill -0 "$pid" 2>/dev/null; do
        n=$("$BUILD/cdem-strain" info "$T/killed.h5" 2>/dev/null |
            sed -n 's/^increments: \([0-9]*\).*/\1/p')
        n=${n:-0}
    done
    kill -9 "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    "$BUILD/cdem-strain" info "$T/killed.h5" 2>/dev/null | grep -q '^stop reason: running' && break
done
cc -std=c17 -D_DEFAULT_SOURCE $(pkg-config --cflags hdf5) tests/fuzz/gen_damaged.c \
    $(pkg-config --libs hdf5) -o "$T/gen_damaged"
"$T/gen_damaged" "$T/complete.h5" "$T/killed.h5" "$OUT"
cp "$T/complete.h5" "$SEEDS/run-tiny"
cp "$T/killed.h5" "$SEEDS/run-killed"
cp "$T/killed.h5" "$OUT/killed.h5" # the fuzz corpus has it as run-killed
cc -std=c17 -D_DEFAULT_SOURCE -Icommon $(pkg-config --cflags hdf5) tests/fuzz/gen_h5_seed.c \
    "$BUILD/libcdem.a" $(pkg-config --libs hdf5) -lm -o "$T/gen_h5_seed"
rm -f "$T/synthetic.h5"
"$T/gen_h5_seed" "$T/synthetic.h5"
cp "$T/synthetic.h5" "$SEEDS/synthetic"
for f in "$OUT"/*.h5; do
    [ "$(basename "$f")" = killed.h5 ] || cp "$f" "$SEEDS/damaged-$(basename "$f" .h5)"
done
ls -l "$OUT" "$SEEDS"
