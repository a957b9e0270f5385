/* run: drives one simulation from parameters to a finished HDF5 file: builds the assembly,
 * equilibrates, applies the boundary mode, writes every display increment, the time series
 * and periodic checkpoints (output.checkpoint_interval), shows progress, and stops cleanly
 * on SIGINT/SIGTERM (finishing the current step, writing a checkpoint, a final increment and
 * a stop reason); cdem_run_resume continues a stored run bit-identically from its newest
 * checkpoint (docs/reliability.md).
 * Ownership: the caller owns params and options. Thread safety: one run per process (the
 * signal flag is the only process-wide state and is owned by main, passed in as a pointer). */
#ifndef CDEM_RUN_H
#define CDEM_RUN_H

#include "cdem_error.h"
#include "h5format.h"
#include "params.h"
#include "snapshot.h"

#include <signal.h>
#include <stdio.h>

typedef struct {
    const char *output_path;               /* HDF5 file to write */
    const char *params_text;               /* original parameter-file text (stored), or NULL */
    int quiet;                             /* 1: no progress output */
    int progress_is_tty;                   /* 1: redraw one progress line; 0: periodic log lines */
    FILE *log;                             /* where progress goes (stderr) */
    volatile sig_atomic_t *stop_requested; /* set to 1 by the signal handler; may be NULL */
    long max_steps;                        /* > 0: stop after this many steps (tests, benchmarks) */
    long par_min;                          /* > 0: the integrator's par_min (loops shorter than this
                                              run on one thread; determinism tests); 0: default */
    int ignore_free_space;                 /* 1: skip the free-space check before the run */
    double dt_factor;        /* tests only (fault injection): > 0 multiplies the derived time step,
                                e.g. 10 to make a run blow up; 0 = the time step of the model */
    cdem_h5_replace replace; /* a file already at output_path: ANY (0) replaces it; cdem-run
                                uses NEVER, or CDEM with --force */
    int no_fsync;            /* 1: no fsync at commits (cdem-run --no-fsync, throwaway runs) */
} cdem_run_options;

/* Checks a run's parameters: every value and rule of the parameter table and the solver's
 * own rules (the growth strata's), all violations in one message (cdem_params_validate). */
cdem_status cdem_run_validate(const cdem_params *p, cdem_error *err);

/* The memory a run of p needs (bytes): CDEM_RUN_MEMORY_FIXED plus CDEM_RUN_MEMORY_PER_ELEMENT
 * for each element cdem_model_estimate_elements expects, the peak resident size measured on
 * cdem-run runs of 2,400 to 1,000,000 elements (docs/performance.md, "Scale"), checkpoints
 * included. */
#define CDEM_RUN_MEMORY_FIXED       (32.0 * 1024 * 1024)
#define CDEM_RUN_MEMORY_PER_ELEMENT 1100.0
double cdem_run_memory_estimate(const cdem_params *p);

/* A model larger than the machine can hold is refused before anything is built
 * (CDEM_ERR_NOMEM, naming the elements, the memory needed and the memory available); a
 * machine whose available memory cannot be read is not refused. There is no other cap on the
 * element count but CDEM_RUN_MAX_ELEMENTS below. */
cdem_status cdem_run_check_memory(const cdem_params *p, cdem_error *err);

/* The one fixed limit on the size of a model: the neighbour list numbers its pairs with
 * 32-bit integers (step/neighbour.h: istart, jslot), and a packing has up to 4 list pairs per
 * element (1.85-2.1 measured, docs/performance.md), so (2^31 - 1) / 4 rounded down; larger
 * models are refused (CDEM_ERR_RANGE) whatever the memory. */
#define CDEM_RUN_MAX_ELEMENTS 500000000L

/* cdem_run_check_memory against `available` bytes instead of the machine's (<= 0: unknown,
 * not refused), and the limit above: what tests call, with the available memory injected. */
cdem_status cdem_run_check_memory_in(const cdem_params *p, double available, cdem_error *err);

/* Runs the model. Returns CDEM_OK when it completed, CDEM_ERR_INTERRUPTED when a stop was
 * requested (the file is valid and says where it stopped), other codes on failure. */
cdem_status cdem_run(const cdem_params *p, const cdem_run_options *opt, cdem_error *err);

/* Resumes the run stored in path (cdem-run --resume): reads its parameters and newest
 * checkpoint, re-opens the file (increments and series after the checkpoint are dropped)
 * and runs to the end; the result is bit-identical to an uninterrupted run. opt's
 * output_path is ignored (the file itself is written). Fails with CDEM_ERR_NOTFOUND when the
 * file has no checkpoint, CDEM_ERR_CONFLICT when the run already completed or was not
 * written by cdem-run, CDEM_ERR_VERSION when another program version or checkpoint layout
 * wrote it; then the file is not modified. */
cdem_status cdem_run_resume(const char *path, const cdem_run_options *opt, cdem_error *err);

/* The staged interface under cdem_run and cdem_run_resume (tests drive it step by step).
 * _open sets the run up; resume NULL starts it fresh (file created when opt->output_path is
 * not NULL, forces primed, increment 0 written), else restores the snapshot (a capture of a
 * run of the same parameters and version) and, with an output path, re-opens that file.
 * _advance runs steps until step until_step or the end (where it writes the final increment
 * and the stop reason "completed"); CDEM_ERR_INTERRUPTED on a stop request. _capture fills
 * snap with the complete run state (every module under its prefix; docs/reliability.md).
 * _close records a failure st in the file, closes it and frees r; returns st or the close
 * error. The context keeps pointers to p and opt until _close. */
typedef struct cdem_run_ctx cdem_run_ctx;
cdem_status cdem_run_open(const cdem_params *p, const cdem_run_options *opt,
                          const cdem_snapshot *resume, cdem_run_ctx **out, cdem_error *err);
cdem_status cdem_run_advance(cdem_run_ctx *r, long until_step, cdem_error *err);
cdem_status cdem_run_capture(const cdem_run_ctx *r, cdem_snapshot *snap, cdem_error *err);
long cdem_run_current_step(const cdem_run_ctx *r);
long cdem_run_total_steps(const cdem_run_ctx *r);
cdem_status cdem_run_close(cdem_run_ctx *r, cdem_status st, cdem_error *err);

/* Counts the elements of increment 0 of the run the parameters describe: free elements and
 * wall, fault and other boundary elements, the latter including those the boundary mode
 * adds (docs/format.md, "Counting"), for the summary; builds the packing and the mode but
 * does not run them. */
cdem_status cdem_run_count_elements(const cdem_params *p, long *n_internal, long *n_wall,
                                    cdem_error *err);

#endif
