#!/bin/bash
# Slurm job array: one cdem-run simulation per array task (a parameter sweep).
#
#   sbatch examples/slurm/sweep.sh                       # from the repository root
#   sbatch --array=0-5 examples/slurm/sweep.sh           # override the range
#
# Each task takes line SLURM_ARRAY_TASK_ID (0-based) of params.txt: a run name followed by
# its -s overrides, e.g.
#     mu0.0  -s material.wall_friction=0.0
#     mu0.3  -s material.wall_friction=0.3
# and writes $OUT/<name>.h5 (+ .xmf) and $OUT/<name>.log. Analyse and render afterwards
# with make (the .h5 files are ordinary make targets), or in a job submitted with
# --dependency=afterok:<array job id>.
#
#SBATCH --job-name=cdem-sweep
#SBATCH --array=0-5
#SBATCH --cpus-per-task=4
#SBATCH --mem=2G
#SBATCH --time=12:00:00
#SBATCH --output=slurm-%A_%a.out
set -euo pipefail

MODEL=${MODEL:-examples/planar/fig7d-detachment.ini}   # the base parameter file
PARAMS=${PARAMS:-examples/slurm/params.txt}            # one run per line
OUT=${OUT:-sweep-out}
CDEM_RUN=${CDEM_RUN:-build/cdem-run}

line=$(grep -v '^[[:space:]]*\(#\|$\)' "$PARAMS" | sed -n "$((SLURM_ARRAY_TASK_ID + 1))p")
[ -n "$line" ] || { echo "no line $SLURM_ARRAY_TASK_ID in $PARAMS"; exit 1; }
read -r name overrides <<< "$line"
mkdir -p "$OUT"

# OpenMP threads = the CPUs Slurm gave this task; results do not depend on the count.
export OMP_NUM_THREADS=${SLURM_CPUS_PER_TASK:-1}
# --force: a task submitted again replaces its earlier result (two tasks writing the same
# name at once are still refused: the second names the first).
# shellcheck disable=SC2086  # the overrides are meant to split into words
"$CDEM_RUN" -q --force "$MODEL" $overrides -o "$OUT/$name.h5" > "$OUT/$name.log" 2>&1
echo "task $SLURM_ARRAY_TASK_ID: $name done: $("${CDEM_STRAIN:-build/cdem-strain}" info "$OUT/$name.h5" | grep '^stop reason')"
