# Sourced by variants.sh and repose6c.sh: the programs, the number of simulations at once and
# their niceness (from the Makefile), and the helpers that make each run of a table once.
RUN=${CDEM_RUN:-../../build/cdem-run}
STRAIN=${CDEM_STRAIN:-../../build/cdem-strain}
JOBS=${JOBS:-2}
NICE=${NICE:-10}
# a variant's name as a folder name
slug() { echo "$1" | tr -c 'A-Za-z0-9.\n' '_'; }
# true when run file $1 exists and completed (a killed run is made again)
done_run() { [ -f "$1" ] && "$STRAIN" info "$1" 2>/dev/null | grep -q "stop reason: completed"; }
# the commands of file $1, one per line, JOBS at a time, one thread each, at nice NICE
run_commands() { OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive xargs -P "$JOBS" -I{} sh -c "nice -n $NICE {}" < "$1"; }
# the last commit that changed the programs (common/, solver/, analysis/)
programs_commit() { git log -1 --format=%h -- ../../common ../../solver ../../analysis 2>/dev/null || echo unknown; }
