#!/bin/bash
# Slurm job array: one cdem-run simulation per array task (a parameter sweep).
#
#   sbatch examples/slurm/sweep.sh                       # from the repository root
#   sbatch --array=0-5 examples/slurm/sweep.sh           # override the range
#   OUT=trial ARGS="-s assembly.half_radii=off -s time.equilibration=400 -s time.runtime=1400" \
#       sbatch examples/slurm/sweep.sh                   # a short trial (seconds per task)
#
# Submit from the repository root: the job runs in the directory sbatch was called from
# (Slurm's default), and the paths below are relative to it (or set them to absolute ones;
# sbatch passes the submitting shell's environment to the job).
#   MODEL       the base parameter file (default examples/planar/fig7d-detachment.ini)
#   PARAMS      one run per line (default examples/slurm/params.txt)
#   OUT         the results folder (default sweep-out)
#   ARGS        extra cdem-run arguments for every task, after the line's own overrides
#   CDEM_RUN, CDEM_STRAIN   the programs (default build/cdem-run, build/cdem-strain)
#
# Each task takes line SLURM_ARRAY_TASK_ID (0-based, comments and blank lines not counted)
# of PARAMS: a run name followed by its -s overrides, e.g.
#     mu0.0  -s material.wall_friction=0.0
#     mu0.3  -s material.wall_friction=0.3
# and writes $OUT/<name>.h5 (+ .xmf) and $OUT/<name>.log; its slurm-<job>_<task>.out ends
# with "task N: <name> done: stop reason: completed: ..." (or the log's last lines if the
# run failed, and the task fails). Analyse and render afterwards with make (the .h5 files
# are ordinary make targets), or in a job submitted with --dependency=afterok:<array job id>.
#
# Verified under Slurm: `make check-slurm` (tests/validate/check_slurm.sh, also run by
# make validate) starts a single-node Slurm 22.05 from Debian's packages, submits this
# script with these #SBATCH lines and params.txt (reduced runs through ARGS), and checks
# every task's .h5, stop reason and .out.
#
# 2 CPUs per task: the solver's OpenMP speed-up is measured up to 2 threads
# (docs/performance.md); ask for more with sbatch --cpus-per-task=N.
#SBATCH --job-name=cdem-sweep
#SBATCH --array=0-5
#SBATCH --cpus-per-task=2
#SBATCH --mem=2G
#SBATCH --time=12:00:00
#SBATCH --output=slurm-%A_%a.out
set -euo pipefail

MODEL=${MODEL:-examples/planar/fig7d-detachment.ini}   # the base parameter file
PARAMS=${PARAMS:-examples/slurm/params.txt}            # one run per line
OUT=${OUT:-sweep-out}
ARGS=${ARGS:-}
CDEM_RUN=${CDEM_RUN:-build/cdem-run}
CDEM_STRAIN=${CDEM_STRAIN:-build/cdem-strain}
task=${SLURM_ARRAY_TASK_ID:?not set: submit with sbatch (a job array)}

for f in "$MODEL" "$PARAMS" "$CDEM_RUN" "$CDEM_STRAIN"; do
    [ -e "$f" ] || { echo "sweep.sh: $f not found in $(pwd) (submit from the repository root" \
        "after make, or set MODEL, PARAMS, CDEM_RUN, CDEM_STRAIN)" >&2; exit 1; }
done

line=$(grep -v '^[[:space:]]*\(#\|$\)' "$PARAMS" | sed -n "$((task + 1))p")
[ -n "$line" ] || { echo "sweep.sh: no line $task in $PARAMS" >&2; exit 1; }
read -r name overrides <<< "$line"
mkdir -p "$OUT"

# OpenMP threads = the CPUs Slurm gave this task; results do not depend on the count.
export OMP_NUM_THREADS=${SLURM_CPUS_PER_TASK:-1}
echo "task $task: $name on $(hostname), $OMP_NUM_THREADS threads: $CDEM_RUN $MODEL $overrides $ARGS"
# --force: a task submitted again replaces its earlier result (two tasks writing the same
# name at once are still refused: the second names the first).
# shellcheck disable=SC2086  # the overrides are meant to split into words
if ! "$CDEM_RUN" -q --force "$MODEL" $overrides $ARGS -o "$OUT/$name.h5" > "$OUT/$name.log" 2>&1; then
    echo "task $task: $name FAILED; the last lines of $OUT/$name.log:" >&2
    tail -n 20 "$OUT/$name.log" >&2
    exit 1
fi
echo "task $task: $name done: $("$CDEM_STRAIN" info "$OUT/$name.h5" | grep '^stop reason')"
