#!/bin/sh
# shellcheck disable=SC2015  # A && B || C: C on either failing is meant throughout
# examples/slurm/sweep.sh under a real Slurm (make check-slurm; make validate runs it too).
#
#   sh tests/validate/check_slurm.sh [BUILD]        (as root, from the repository root)
#
# Starts a private single-node Slurm from Debian's packages and runs the documented sweep
# through it:
#  1. installs slurmctld, slurmd, slurm-client and munge with apt-get when they are missing
#     (services are kept from starting at install: policy-rc.d);
#  2. writes a munge key and a one-node slurm.conf (this host, its CPUs and memory, no
#     cgroups: proctrack/linuxproc, task/none, select/cons_tres) into a scratch folder that
#     also holds the state, spool, logs, pid files and the munge socket, on free ports, so
#     nothing of the machine's own Slurm or munge (if any) is used or touched;
#  3. starts munged, slurmctld and slurmd in the background and waits until sinfo shows
#     the node idle;
#  4. from the repository root, submits `sbatch examples/slurm/sweep.sh` with its own
#     #SBATCH lines and params.txt (6 tasks), but short runs (ARGS: a 10 x 2.5 km model,
#     400 s; a few seconds each), OUT and the task .out files in the scratch folder;
#  5. waits for the array (squeue; CHECK_SLURM_TIMEOUT seconds, default 900) and checks
#     every task: state COMPLETED, its .h5 exists, `cdem-strain info` says "stop reason:
#     completed", its slurm-<job>_<task>.out says "task N: <name> done: stop reason:
#     completed";
#  6. always (trap): cancels what is left, stops slurmd, slurmctld and munged and removes
#     the scratch folder (CHECK_SLURM_KEEP=1 keeps it).
# Where Slurm cannot be had (not root, no apt-get or Debian mirror, daemons that do not
# start) it prints "check-slurm: SKIPPED: <why>" as its last line and exits 0;
# CHECK_SLURM_NO_INSTALL=1 skips instead of installing. Once Slurm runs, any failure of the
# sweep exits 1.
BUILD=${1:-build}
TIMEOUT=${CHECK_SLURM_TIMEOUT:-900}
# Reduced runs: every task the same small model (the params.txt line's own overrides too).
ARGS_SHORT="-s assembly.width=10 -s assembly.height=2.5 -s assembly.half_radii=off \
-s time.equilibration=200 -s time.runtime=400 -s time.display_interval=50"

say() { echo "check-slurm: $*"; }
fail() { say "FAILED: $*"; exit 1; }
S=; POLICY=; MUNGED_PID=; CTLD_PID=; SLURMD_PID=; JOB=

# stop PID NAME: SIGTERM, up to 15 s, then SIGKILL
stop() {
    [ -n "$1" ] && kill -0 "$1" 2>/dev/null || return 0
    kill "$1" 2>/dev/null
    i=0
    while kill -0 "$1" 2>/dev/null && [ $i -lt 30 ]; do sleep 0.5; i=$((i + 1)); done
    if kill -0 "$1" 2>/dev/null; then
        say "$2 (pid $1) did not stop on SIGTERM; killing it"
        kill -9 "$1" 2>/dev/null
    fi
    wait "$1" 2>/dev/null
    return 0
}

cleanup() {
    rc=$?
    trap - EXIT INT TERM HUP
    [ -n "$POLICY" ] && rm -f "$POLICY"
    if [ -n "$JOB" ] && [ -n "$CTLD_PID" ] && kill -0 "$CTLD_PID" 2>/dev/null; then
        if [ -n "$(squeue -h -j "$JOB" -o %i 2>/dev/null)" ]; then
            scancel "$JOB" 2>/dev/null
            i=0  # let slurmd end the tasks' processes before it stops
            while [ -n "$(squeue -h -j "$JOB" -o %i 2>/dev/null)" ] && [ $i -lt 60 ]; do
                sleep 0.5; i=$((i + 1))
            done
        fi
    fi
    stop "$SLURMD_PID" slurmd
    stop "$CTLD_PID" slurmctld
    stop "$MUNGED_PID" munged
    if [ -n "$S" ]; then
        if [ "${CHECK_SLURM_KEEP:-0}" = 1 ]; then say "kept $S"; else rm -rf "$S"; fi
    fi
    exit $rc
}
trap cleanup EXIT
trap 'say "interrupted (SIGINT): stopping Slurm"; exit 130' INT
trap 'say "terminated (SIGTERM): stopping Slurm"; exit 143' TERM
trap 'say "hung up (SIGHUP): stopping Slurm"; exit 129' HUP

# skip WHY [LOG...]: the last lines of each log, then the one SKIPPED line; exit 0
skip() {
    why=$1; shift
    for log in "$@"; do
        [ -s "$log" ] && { echo "--- last lines of $(basename "$log"):"; tail -n 15 "$log"; }
    done
    say "SKIPPED: $why"
    exit 0
}

[ -x "$BUILD/cdem-run" ] && [ -x "$BUILD/cdem-strain" ] ||
    fail "$BUILD/cdem-run or $BUILD/cdem-strain is not built (make)"
[ -f examples/slurm/sweep.sh ] || fail "run from the repository root"

# 1. Debian's packages
[ "$(id -u)" = 0 ] || skip "needs root (to install Debian's slurm packages and run slurmd)"
missing=
for c in slurmctld:slurmctld slurmd:slurmd sbatch:slurm-client squeue:slurm-client \
         sinfo:slurm-client scancel:slurm-client munged:munge munge:munge; do
    command -v "${c%%:*}" >/dev/null 2>&1 || case " $missing " in
        *" ${c#*:} "*) ;; *) missing="$missing ${c#*:}" ;; esac
done
if [ -n "$missing" ]; then
    [ "${CHECK_SLURM_NO_INSTALL:-0}" = 1 ] &&
        skip "not installed:$missing (CHECK_SLURM_NO_INSTALL=1)"
    command -v apt-get >/dev/null 2>&1 || skip "not installed:$missing, and no apt-get"
    say "installing$missing (apt-get)"
    if [ ! -e /usr/sbin/policy-rc.d ]; then  # packages must not start the system's daemons
        POLICY=/usr/sbin/policy-rc.d
        printf '#!/bin/sh\nexit 101\n' > "$POLICY" && chmod 755 "$POLICY"
    fi
    # shellcheck disable=SC2086
    if ! DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
            $missing >/dev/null 2>&1; then
        DEBIAN_FRONTEND=noninteractive apt-get update -q >/dev/null 2>&1
        # shellcheck disable=SC2086
        DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
            $missing >/dev/null 2>&1 ||
            skip "apt-get install$missing failed (no network to the Debian mirror?)"
    fi
    [ -n "$POLICY" ] && rm -f "$POLICY"; POLICY=
fi
say "$(slurmctld -V 2>&1), $(munged -V 2>&1 | head -n 1)"

# 2. the scratch folder: key, configuration, state, logs
S=$(mktemp -d "${TMPDIR:-/tmp}/cdem-slurm.XXXXXX") || fail "mktemp -d failed"
chmod 700 "$S"
mkdir -p "$S/munge" "$S/state" "$S/spool" "$S/out" && chmod 700 "$S/munge" || fail "mkdir in $S"
dd if=/dev/urandom of="$S/munge/munge.key" bs=1024 count=1 2>/dev/null &&
    chmod 400 "$S/munge/munge.key" || fail "cannot write the munge key"
HOST=$(hostname -s)
# this machine's CPUs, sockets, cores and memory, as slurmd sees them
NODE=$(slurmd -C 2>/dev/null | sed -n 's/^NodeName=[^ ]* //p')
[ -n "$NODE" ] || skip "slurmd -C does not describe this machine"
# two free TCP ports on the loopback (the defaults 6817/6818 may belong to a real Slurm)
PORTS=$(/usr/bin/python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*(x.getsockname()[1] for x in s))') || fail "no free ports"
CTLD_PORT=${PORTS% *}; SLURMD_PORT=${PORTS#* }
: > "$S/plugstack.conf"
cat > "$S/slurm.conf" <<EOF
# single-node Slurm of tests/validate/check_slurm.sh
ClusterName=cdemcheck
SlurmctldHost=$HOST(127.0.0.1)
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$S/munge/munge.socket
StateSaveLocation=$S/state
SlurmdSpoolDir=$S/spool
SlurmctldPidFile=$S/slurmctld.pid
SlurmdPidFile=$S/slurmd.pid
SlurmctldLogFile=$S/slurmctld.log
SlurmdLogFile=$S/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
PlugStackConfig=$S/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
# no accounting storage, job completion log, switch or MPI plugins: the defaults
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MinJobAge=3600
NodeName=$HOST NodeAddr=127.0.0.1 $NODE State=UNKNOWN
PartitionName=check Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$S/slurm.conf"

# 3. the daemons, each in the foreground of its own background process
munged -F -f --socket="$S/munge/munge.socket" --key-file="$S/munge/munge.key" \
    --pid-file="$S/munge/munged.pid" --log-file="$S/munge/munged.log" \
    --seed-file="$S/munge/munged.seed" > "$S/munged.out" 2>&1 &
MUNGED_PID=$!
i=0
until munge -n -S "$S/munge/munge.socket" 2>/dev/null | unmunge -S "$S/munge/munge.socket" \
        >/dev/null 2>&1; do
    kill -0 $MUNGED_PID 2>/dev/null && [ $i -lt 40 ] ||
        skip "munged does not start" "$S/munged.out" "$S/munge/munged.log"
    sleep 0.5; i=$((i + 1))
done
slurmctld -D -c -f "$SLURM_CONF" > "$S/slurmctld.out" 2>&1 &
CTLD_PID=$!
slurmd -D -f "$SLURM_CONF" -N "$HOST" > "$S/slurmd.out" 2>&1 &
SLURMD_PID=$!
i=0
state=
while [ "$state" != idle ]; do
    kill -0 $CTLD_PID 2>/dev/null ||
        skip "slurmctld exited" "$S/slurmctld.out" "$S/slurmctld.log"
    kill -0 $SLURMD_PID 2>/dev/null || skip "slurmd exited" "$S/slurmd.out" "$S/slurmd.log"
    [ $i -lt 120 ] || skip "node $HOST not idle after 60 s (sinfo: ${state:-nothing})" \
        "$S/slurmctld.log" "$S/slurmd.log"
    sleep 0.5; i=$((i + 1))
    state=$(sinfo -h -N -n "$HOST" -o %T 2>/dev/null)
done
say "Slurm up: node $HOST ($NODE) idle, controller port $CTLD_PORT"

# 4. the documented submission, from the repository root
names=$(grep -v '^[[:space:]]*\(#\|$\)' examples/slurm/params.txt | awk '{ print $1 }')
ntasks=$(echo "$names" | wc -l)
JOB=$(OUT="$S/out" ARGS="$ARGS_SHORT" CDEM_RUN="$BUILD/cdem-run" \
    CDEM_STRAIN="$BUILD/cdem-strain" sbatch --parsable --output="$S/slurm-%A_%a.out" \
    examples/slurm/sweep.sh 2>"$S/sbatch.err") ||
    fail "sbatch examples/slurm/sweep.sh: $(cat "$S/sbatch.err")"
JOB=${JOB%%;*}
say "submitted array job $JOB ($ntasks tasks of params.txt, short runs)"

# 5. wait for every task to end
start=$(date +%s)
last=
while :; do
    states=$(squeue -h -r -j "$JOB" -t all -o '%i %T' 2>/dev/null | sort -t_ -k2n)
    [ -n "$states" ] || fail "squeue does not know job $JOB"
    summary=$(echo "$states" | awk '{ print $2 }' | sort | uniq -c | awk '{ printf " %s %s", $1, $2 }')
    [ "$summary" != "$last" ] && say "job $JOB:$summary ($(($(date +%s) - start)) s)"
    last=$summary
    echo "$states" | awk '{ print $2 }' |
        grep -qv -E '^(COMPLETED|FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY|BOOT_FAIL|DEADLINE|PREEMPTED)$' ||
        break
    [ $(($(date +%s) - start)) -lt "$TIMEOUT" ] ||
        fail "job $JOB not finished after $TIMEOUT s (CHECK_SLURM_TIMEOUT):$summary"
    sleep 1
done

# 6. every task's result
bad=0
t=0
for name in $names; do
    out="$S/slurm-${JOB}_$t.out"
    h5="$S/out/$name.h5"
    st=$(echo "$states" | awk -v id="${JOB}_$t" '$1 == id { print $2 }')
    problem=
    if [ "$st" != COMPLETED ]; then problem="state ${st:-unknown}"
    elif [ ! -s "$h5" ]; then problem="no $name.h5"
    elif ! "$BUILD/cdem-strain" info "$h5" 2>&1 | grep -q '^stop reason: completed'; then
        problem="cdem-strain info: $("$BUILD/cdem-strain" info "$h5" 2>&1 | grep '^stop reason' || echo 'no stop reason')"
    elif ! grep -q "^task $t: $name done: stop reason: completed" "$out" 2>/dev/null; then
        problem="$(basename "$out") does not say 'task $t: $name done: stop reason: completed'"
    fi
    if [ -z "$problem" ]; then
        say "task $t: OK: $(tail -n 1 "$out")"
    else
        bad=$((bad + 1))
        say "task $t ($name): FAILED: $problem"
        [ -f "$out" ] && { echo "--- $(basename "$out"):"; tail -n 20 "$out"; }
        [ ! -f "$out" ] && [ -f "$S/out/$name.log" ] && { echo "--- $name.log:"; tail -n 20 "$S/out/$name.log"; }
    fi
    t=$((t + 1))
done
[ "$bad" -eq 0 ] || fail "$bad of $ntasks tasks of job $JOB failed"
say "OK: sbatch examples/slurm/sweep.sh ran all $ntasks tasks under Slurm ($(slurmctld -V 2>&1), one node), every .h5 completed, $(($(date +%s) - start)) s"
