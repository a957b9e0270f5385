#!/bin/sh
# Kill campaign (issue 46; docs/reliability.md, "Round four (issue 46)", "Audit re-run"):
# cdem-run SIGKILLed at N seeded moments, and every file it leaves checked as the audit did.
#
# Usage: sh tests/validate/kill_campaign.sh [-n N] [--seed S] [--build DIR] [--dir DIR] [--keep]
#   -n N         kills (default 100), spread round-robin over three small models
#                (1269-1274 elements, 21-23 increments, a checkpoint every 2 increments):
#                plain   the small test model (planar normal fault);
#                salt    with a basal salt layer, contact damping and a detachment;
#                actors  two boundary actors: the planar fault stops at 15 m and a second
#                        planar fault at 0.25 of the base takes over;
#   --seed S     seed of the kill moments (default 46); the same seed gives the same moments
#                relative to the measured run time;
#   --build DIR  where cdem-run and cdem-strain are (default build);
#   --dir DIR    work folder (default a new folder under ${TMPDIR:-/tmp}); it is removed at
#                the end unless something failed or --keep is given;
#   --keep       keep the work folder;
#   --limit S    the time limit of each step after the kill (default 20 T + 60 s, T the
#                slowest straight run), beyond which the step is a hang.
#
# For each model the run is first made straight (its file is the reference, its wall time T
# measured). Kill K runs model K mod 3 and SIGKILLs it after a delay of T x (0.01 .. 0.95),
# drawn from the seed and K. Then, each step under a time limit (a hang: 20 T + 60 s):
#  (a) the file opens: `cdem-strain info FILE` exits 0 and says "interrupted (no writer holds
#      it)" (a run that finished before the kill: "completed"), with no "damaged:" line;
#      a kill before the file was put in place (NAME.creating only) is counted as "no file";
#  (b) its committed increments (the valid rows of /increments/commit, counted from the file's
#      bytes, as many as `info --json` lists) each read back identical to the straight run's
#      increment of the same number (row members and every element dataset, bit for bit),
#      and its series is a prefix of the straight run's (kill_campaign.py committed);
#  (c) `cdem-run -q --resume FILE` ends with the straight run's file (every object, attribute
#      and dataset equal, the root attribute `created` left out: kill_campaign.py same);
#      a file killed before its first checkpoint is refused ("has no checkpoint to resume
#      from", exit 1) and counted as a refusal (a refusal of a file with more than 3
#      committed increments is a failure: increment 2's checkpoint must be there); a run
#      that completed before the kill is compared as it is.
# A crash is an exit status above 128 of any step (the kill itself excepted). Prints one line
# per kill and a summary table; exits 1 on any failure, keeping the work folder with the
# killed file (KILL.h5.killed, as the kill left it), the logs and the command of each step.
set -u

N=100; SEED=46; BUILD=build; DIR=; KEEP=0; LIMIT_SET=
while [ $# -gt 0 ]; do
    case $1 in
        -n) N=$2; shift 2 ;;
        --seed) SEED=$2; shift 2 ;;
        --build) BUILD=$2; shift 2 ;;
        --dir) DIR=$2; shift 2 ;;
        --keep) KEEP=1; shift ;;
        --limit) LIMIT_SET=$2; shift 2 ;;
        -h|--help) sed -n '2,40p' "$0"; exit 0 ;;
        *) echo "kill_campaign: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
done
case $N in ''|*[!0-9]*) echo "kill_campaign: -n needs a number" >&2; exit 2 ;; esac
case $SEED in ''|*[!0-9]*) echo "kill_campaign: --seed needs a number" >&2; exit 2 ;; esac

HERE=$(cd "$(dirname "$0")" && pwd)
BUILD=$(cd "$BUILD" 2>/dev/null && pwd) || { echo "kill_campaign: no build folder" >&2; exit 1; }
RUN=$BUILD/cdem-run; STRAIN=$BUILD/cdem-strain
PY="/usr/bin/python3 $HERE/kill_campaign.py"
for b in "$RUN" "$STRAIN"; do
    [ -x "$b" ] || { echo "kill_campaign: $b is not built (make -j2 all)" >&2; exit 1; }
done
if [ -z "$DIR" ]; then
    DIR=$(mktemp -d "${TMPDIR:-/tmp}/kill_campaign.XXXXXX") || exit 1
else
    mkdir -p "$DIR" || exit 1
fi
DIR=$(cd "$DIR" && pwd)
cd "$DIR" || exit 1
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive} OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
export HDF5_USE_FILE_LOCKING=FALSE # h5py only reads; cdem-run and cdem-strain set their own

BASE="-q -s assembly.width=10 -s assembly.height=2.5 -s time.equilibration=100 \
-s time.runtime=150 -s output.checkpoint_interval=2"
model_name() { case $1 in 0) echo plain ;; 1) echo salt ;; 2) echo actors ;; esac; }
model_args() {
    case $1 in
        0) echo "$BASE" ;;
        1) echo "$BASE -s salt.layer=basal -s physics.damping_mode=contact -s boundary.mode=detachment" ;;
        2) echo "$BASE -s boundary.stop=15 -s boundary.2.mode=planar-fault \
-s boundary.2.fault_location=0.25 -s boundary.2.start=15" ;;
    esac
}
now() { date +%s.%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }

# A step under the time limit: runs "$@" with stdout and stderr to $LOG; sets RC and ELAPSED.
# A step that outlives its limit is killed (timeout: TERM, then KILL 5 s later): RC 124.
LIMIT=60
step() {
    t0=$(now)
    timeout -k 5 "$LIMIT" "$@" >"$LOG" 2>&1
    RC=$?
    ELAPSED=$(secs "$t0" "$(now)")
    if [ "$RC" -eq 137 ] && awk -v e="$ELAPSED" -v l="$LIMIT" 'BEGIN { exit !(e >= l) }'; then
        RC=124 # TERM was not enough: KILLed by timeout
    fi
}

# 1. The straight runs: reference files and wall times.
echo "kill_campaign: $N kills, seed $SEED, work folder $DIR"
TMAX=0
for m in 0 1 2; do
    name=$(model_name $m)
    LOG=straight-$name.log
    LIMIT=3600
    # shellcheck disable=SC2046
    step "$RUN" $(model_args $m) -o "straight-$name.h5"
    if [ "$RC" -ne 0 ]; then
        echo "kill_campaign: the straight $name run failed (exit $RC):"; tail -n 20 "$LOG"
        exit 1
    fi
    eval "T$m=$ELAPSED"
    TMAX=$(awk -v a="$TMAX" -v b="$ELAPSED" 'BEGIN { print (b > a ? b : a) }')
    "$STRAIN" info --json "straight-$name.h5" >"straight-$name.json" 2>&1
    echo "kill_campaign: straight $name run: $ELAPSED s," \
        "$(sed -n 's/.*"increment_count": \([0-9]*\).*/\1/p' "straight-$name.json") increments"
done
LIMIT=${LIMIT_SET:-$(awk -v t="$TMAX" 'BEGIN { printf "%d", 20 * t + 60 }')}
echo "kill_campaign: time limit per step $LIMIT s (a step that takes longer is a hang)"

# The kill moment of kill K as a fraction 0.01 .. 0.95 of the run time: a 32-bit integer hash
# (two multiply-xorshift rounds) of SEED and K, in the shell's 64-bit arithmetic (the
# products stay below 2^59). The runs killed late may complete first on a less loaded
# machine; they are counted apart.
fraction() {
    x=$(( (SEED * 1000003 + $1) & 4294967295 ))
    x=$(( x ^ (x >> 16) )); x=$(( (x * 73244475) & 4294967295 ))
    x=$(( x ^ (x >> 16) )); x=$(( (x * 73244475) & 4294967295 ))
    x=$(( x ^ (x >> 16) ))
    awk -v x="$x" 'BEGIN { printf "%.4f", 0.01 + 0.94 * x / 4294967296 }'
}

kills=0 files=0 nofile=0 opened=0 inc_total=0 inc_same=0 finished=0
res_possible=0 res_same=0 refusals=0 crashes=0 hangs=0 failures=0
FAILED=""
printed=-1
fail() { # kill, what (after the kill's line, printed once)
    [ "$printed" = "$K" ] || { echo "$line"; printed=$K; }
    failures=$((failures + 1)); FAILED="$FAILED
  kill $1 ($NAME, killed at $DELAY s): $2"
    echo "    FAILED: $2"
}
# After a step: counts a crash or a hang of it; returns 1 when it was one.
judge() { # what
    if [ "$RC" -eq 124 ]; then
        hangs=$((hangs + 1)); fail "$K" "$1 hung (over $LIMIT s; log $DIR/$LOG)"; return 1
    fi
    if [ "$RC" -gt 128 ]; then
        crashes=$((crashes + 1)); fail "$K" "$1 crashed (exit $RC; log $DIR/$LOG)"; return 1
    fi
    return 0
}

# 2. The kills. one_kill runs kill $K; it returns early at a failure or a refusal.
one_kill() {
    m=$((K % 3)); NAME=$(model_name $m); eval "T=\$T$m"
    F=kill$K.h5; REF=straight-$NAME.h5
    DELAY=$(awk -v t="$T" -v f="$(fraction "$K")" 'BEGIN { printf "%.3f", t * f }')
    kills=$((kills + 1))
    echo "cdem-run $(model_args $m) -o $F  # SIGKILLed after $DELAY s" >"kill$K.cmd"
    # shellcheck disable=SC2046
    "$RUN" $(model_args $m) -o "$F" >"kill$K.run.log" 2>&1 &
    pid=$!
    sleep "$DELAY"
    kill -KILL "$pid" 2>/dev/null
    { wait "$pid"; } 2>/dev/null # (no "Killed" from the shell)
    st=$?
    line="kill $K: $NAME at $DELAY s"
    if [ "$st" -eq 0 ]; then
        line="$line (the run had completed)"
    elif [ "$st" -ne 137 ]; then
        echo "$line"
        [ "$st" -gt 128 ] && crashes=$((crashes + 1))
        fail "$K" "cdem-run ended with exit status $st before the kill (log $DIR/kill$K.run.log)"
        return
    fi
    if [ ! -e "$F" ]; then
        nofile=$((nofile + 1))
        echo "$line: no file yet ($([ -e "$F.creating" ] && echo "$F.creating left" || echo "nothing left"))"
        return
    fi
    files=$((files + 1))
    cp "$F" "$F.killed"

    # (a) the file opens
    LOG=kill$K.info.log
    step "$STRAIN" info "$F"
    judge "cdem-strain info $F" || return
    if [ "$RC" -ne 0 ]; then
        fail "$K" "cdem-strain info $F: exit $RC: $(head -n 3 "$LOG" | tr '\n' ' ')"
        return
    fi
    opened=$((opened + 1))
    if grep -q '^damaged:' "$LOG"; then
        fail "$K" "cdem-strain info reports damage: $(grep '^damaged:' "$LOG")"
    fi
    completed=0 # completed before the kill (or killed while it compacted the completed file)
    if grep -q '^stop reason: completed' "$LOG"; then
        completed=1; finished=$((finished + 1))
    elif [ "$st" -eq 0 ] || ! grep -q '^stop reason: interrupted (no writer holds it)' "$LOG"; then
        fail "$K" "cdem-strain info: $(grep '^stop reason' "$LOG") (exit status of the run $st)"
    fi

    # (b) the committed increments
    "$STRAIN" info --json "$F" >"kill$K.json" 2>"kill$K.json.err"
    LOG=kill$K.committed.log
    step $PY committed "$F" "$REF" "kill$K.json"
    judge "the comparison of the committed increments" || return
    c=$(sed -n '1s/^committed \([0-9]*\) identical \([0-9]*\) series.*/\1/p' "$LOG")
    s=$(sed -n '1s/^committed \([0-9]*\) identical \([0-9]*\) series.*/\2/p' "$LOG")
    c=${c:-0}; s=${s:-0}
    inc_total=$((inc_total + c)); inc_same=$((inc_same + s))
    line="$line: opens, $c committed, $s identical, $(sed -n '1s/.* series \([a-z]*\).*/series prefix \1/p' "$LOG")"
    if [ "$RC" -ne 0 ]; then
        fail "$K" "committed increments: $(sed -n '1,6p' "$LOG" | tr '\n' ' ')"
    fi

    # (c) the resume
    if [ "$completed" -eq 1 ]; then # already the straight run's file
        LOG=kill$K.same.log
        ic=
        /usr/bin/python3 -c "import h5py, sys
with h5py.File(sys.argv[1], 'r', swmr=True) as f: sys.exit('dropped' in f['checkpoint'].attrs)" \
            "$F" 2>/dev/null && ic=--ignore-checkpoint
        step $PY same "$F" "$REF" $ic
        judge "the comparison with the straight run" || return
        if [ "$RC" -ne 0 ]; then
            echo "$line"
            fail "$K" "completed file differs from the straight run: $(sed -n '2,6p' "$LOG" | tr '\n' ' ')"
        else
            echo "$line; completed before the kill: the straight run's file${ic:+ (checkpoints kept)}"
        fi
        return
    fi
    LOG=kill$K.resume.log
    echo "cdem-run -q --resume $F" >>"kill$K.cmd"
    step "$RUN" -q --resume "$F"
    judge "cdem-run --resume" || return
    if [ "$RC" -ne 0 ]; then
        if [ "$RC" -eq 1 ] && grep -q "has no checkpoint to resume from" "$LOG"; then
            refusals=$((refusals + 1))
            if [ "$c" -gt 3 ]; then
                fail "$K" "--resume refused for want of a checkpoint with $c committed increments"
            elif ! cmp -s "$F" "$F.killed"; then
                fail "$K" "--resume refused but changed the file"
            else
                echo "$line; resume refused: no checkpoint yet (file unchanged)"
            fi
        else
            fail "$K" "--resume: exit $RC: $(tail -n 3 "$LOG" | tr '\n' ' ')"
        fi
        return
    fi
    res_possible=$((res_possible + 1))
    LOG=kill$K.same.log
    step $PY same "$F" "$REF"
    judge "the comparison with the straight run" || return
    if [ "$RC" -eq 0 ]; then
        res_same=$((res_same + 1)); echo "$line; resumed: identical to the straight run"
    else
        fail "$K" "resumed file differs from the straight run: $(sed -n '2,8p' "$LOG" | tr '\n' ' ')"
    fi
}

K=0
while [ "$K" -lt "$N" ]; do
    before=$failures
    one_kill
    # a kill without failure leaves nothing behind; a failed one keeps its files and logs
    [ "$failures" -eq "$before" ] && rm -f "kill$K".* "kill$K.h5".*
    K=$((K + 1))
done

# 3. The summary.
cat <<EOF

kill_campaign: seed $SEED, straight runs plain $T0 s, salt $T1 s, actors $T2 s
| kills | files left (open) | no file yet | completed before the kill | committed increments (identical) | resumes possible (identical) | refused: no checkpoint yet | crashes | hangs |
|---|---|---|---|---|---|---|---|---|
| $kills | $files ($opened) | $nofile | $finished | $inc_total ($inc_same) | $res_possible ($res_same) | $refusals | $crashes | $hangs |
EOF
if [ "$failures" -gt 0 ]; then
    echo "kill_campaign: $failures FAILED (files, logs and commands kept in $DIR):$FAILED"
    exit 1
fi
echo "kill_campaign: all held: $kills kills, $opened/$files files open ($nofile before the file" \
    "existed), $inc_same/$inc_total committed increments identical, $res_same/$res_possible" \
    "resumes identical, $refusals refused (no checkpoint yet), $crashes crashes, $hangs hangs"
if [ "$KEEP" -eq 0 ]; then cd / && rm -rf "$DIR"; fi
exit 0
