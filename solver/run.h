/* run: drives one simulation from parameters to a finished HDF5 file: builds the assembly,
 * equilibrates, applies the boundary mode, writes every display increment and the time
 * series, shows progress, and stops cleanly on SIGINT/SIGTERM (finishing the current step,
 * writing a final increment and a stop reason).
 * Ownership: the caller owns params and options. Thread safety: one run per process (the
 * signal flag is the only process-wide state and is owned by main, passed in as a pointer). */
#ifndef CDEM_RUN_H
#define CDEM_RUN_H

#include "cdem_error.h"
#include "params.h"

#include <signal.h>
#include <stdio.h>

typedef struct {
    const char *output_path;         /* HDF5 file to write */
    const char *params_text;         /* original parameter-file text (stored), or NULL */
    int quiet;                       /* 1: no progress output */
    int progress_is_tty;             /* 1: redraw one progress line; 0: periodic log lines */
    FILE *log;                       /* where progress goes (stderr) */
    volatile sig_atomic_t *stop_requested; /* set to 1 by the signal handler; may be NULL */
    long max_steps;                  /* > 0: stop after this many steps (tests, benchmarks) */
    double dt_factor; /* tests only (fault injection): > 0 multiplies the derived time step,
                         e.g. 10 to make a run blow up; 0 = the time step of the model */
} cdem_run_options;

/* Runs the model. Returns CDEM_OK when it completed, CDEM_ERR_INTERRUPTED when a stop was
 * requested (the file is valid and says where it stopped), other codes on failure. */
cdem_status cdem_run(const cdem_params *p, const cdem_run_options *opt, cdem_error *err);

/* Counts the elements of the assembly the parameters generate (internal and wall), for the
 * summary; generates the packing but does not run it. */
cdem_status cdem_run_count_elements(const cdem_params *p, long *n_internal, long *n_wall,
                                    cdem_error *err);

#endif
