/* calib_runs: the simulations of cdem-strain calibrate: each an ordinary cdem-run process
 * writing an ordinary run file in the calibration's work folder, kept for inspection.
 *
 * cdem-strain links no solver code (Makefile: the analysis never sees solver/), so the
 * biaxial tests are run by the cdem-run program: the one named by --cdem-run, else the one
 * next to this cdem-strain (build/ holds both, and so does an installed bin/), else the
 * first on PATH.
 *
 * A run file found in the folder is judged by its stop reason: "completed" is finished and
 * only read; "interrupted", or "running" with no writer holding it (killed), is continued
 * with `cdem-run --resume` when it holds a checkpoint and run again otherwise; a file a
 * writer holds (a run of an earlier calibrate that is still going, or a Slurm task) is
 * waited for; a file that cannot be opened (killed before its first write) is run again
 * (--force). Any other stop reason (numerical-failure, error, ...) fails the calibration,
 * naming the file and its log.
 *
 * Locally the runs go at most `jobs` at a time, each under nice, with OMP_NUM_THREADS set to
 * the cores over the jobs (unless the environment sets it) and OMP_WAIT_POLICY=passive (idle
 * threads sleep: the machine is shared); each child asks the kernel for SIGTERM when
 * calibrate dies (prctl PR_SET_PDEATHSIG), so a killed calibration leaves interrupted runs,
 * which the next one resumes. With a Slurm sweep script (examples/slurm/sweep.sh) the runs
 * still to do are one job array (`sbatch --wait --array=0-N`), the script's PARAMS file
 * written into the folder; the script re-runs a task from its start (--force).
 * Ownership: the caller owns the run table; nothing is kept between calls. Thread safety:
 * one call at a time (it forks and waits for its children). */
#ifndef CDEM_CALIB_RUNS_H
#define CDEM_CALIB_RUNS_H

#include "cdem_error.h"

#include <stddef.h>
#include <stdio.h>

#define CDEM_CALIB_PATH_MAX 1024
#define CDEM_CALIB_MAX_SETS 16 /* -s overrides passed to every run */

/* One simulation: its file and the overrides that make it. */
typedef struct {
    char path[CDEM_CALIB_PATH_MAX]; /* DIR/NAME.h5 */
    char name[256];                 /* NAME */
    char sets[4][96];               /* its own -s overrides: friction, cohesion, seed, pressure */
    int n_sets;
    int ran; /* out: 1 when this call ran or resumed it */
} cdem_calib_run;

typedef struct {
    const char *cdem_run;    /* the cdem-run program (cdem_calib_find_cdem_run) */
    const char *model;       /* the model file the runs use (DIR/model.ini) */
    const char *dir;         /* the work folder */
    const char *const *sets; /* -s overrides for every run, after each run's own */
    size_t n_sets;
    int jobs;                 /* runs at once, >= 1 */
    int nice;                 /* niceness of the runs, 0..19 */
    const char *slurm_script; /* NULL: local processes; else the sweep script (sbatch) */
    const char *cdem_strain;  /* the sweep script's CDEM_STRAIN: this program */
    FILE *progress;           /* one line per run started or resumed (may be NULL) */
} cdem_calib_runner;

/* The cdem-run program into path: `given` when not NULL (it must be executable), else
 * cdem-run next to this program (/proc/self/exe), else the first on PATH. */
cdem_status cdem_calib_find_cdem_run(const char *given, char *path, size_t cap, cdem_error *err);

/* This program's own path (for the sweep script's CDEM_STRAIN), or "cdem-strain". */
void cdem_calib_self(char *path, size_t cap);

/* Brings every run to "completed": reads each file's state, runs, resumes or waits for
 * those not finished (see above), then checks every file again. *n_ran gets the number of
 * runs run or resumed now, each counted once (a run killed and resumed is one run). Fails naming
 * the first run that did not complete and its log's last lines. */
cdem_status cdem_calib_complete(const cdem_calib_runner *r, cdem_calib_run *runs, size_t n,
                                size_t *n_ran, cdem_error *err);

/* The counts of a design point's runs in words, into buf: "1 run, it was run now", "2 runs,
 * all run now", "3 runs, 1 of them run now", "2 runs, none run now" (read from finished
 * files). n_ran is clamped to n_runs. */
void cdem_calib_count_text(size_t n_runs, size_t n_ran, char *buf, size_t cap);

/* The stop reason of a run file in *reason ("" when it cannot be opened: not yet written),
 * and whether a writer holds it (1), none (0) or it cannot be told (-1). */
void cdem_calib_file_state(const char *path, char *reason, size_t cap, int *alive);

#endif
