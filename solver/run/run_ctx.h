/* run_ctx: what the files of the run loop share, and nothing outside them includes. The
 * public interface is run.h. One responsibility per file: run.c (set-up, the loop over the
 * steps and its events, open/advance/close, cdem_run and cdem_run_resume), run_output.c (the
 * increments with the erosion due before them, the time-series samples and the summary text
 * of the file), run_progress.c (the progress display and the log lines that end a run) and
 * run_ckpt.c (checkpoints: capture, restore, the periodic and the stop checkpoints).
 * The run context holds each file's own state in a group of its own (prog, ckpt); the rest is
 * the run itself. Names are run_*: internal, global only because the run spans several files.
 * Ownership, threads, units: as run.h (one run per process; SI units). */
#ifndef CDEM_RUN_CTX_H
#define CDEM_RUN_CTX_H

#include "assembly.h"
#include "bc.h"
#include "cdem_error.h"
#include "governor.h"
#include "h5format.h"
#include "integrate.h"
#include "model.h"
#include "process.h"
#include "run.h"
#include "sediment.h"
#include "snapshot.h"
#include "state.h"

#ifndef CDEM_VERSION
#define CDEM_VERSION "0.0.0"
#endif

/* The progress display's state (run_progress.c; the wall clock it reads never reaches a
 * result). */
typedef struct {
    long step0;                 /* step at which this process started (progress rate only) */
    double t_start, t_last_log; /* s, monotonic clock */
    long last_log_step;         /* step of the last progress output */
    /* measured speed of each phase: equilibration and deformation (with settling) run at
     * different speeds, so the time left adds up each phase's own */
    double phase_time[2]; /* s spent in [0] equilibration, [1] deformation and settling */
    long phase_steps[2];  /* steps taken in each */
    double t_mark;        /* s, clock at the last accounting */
    long mark_step;       /* step at the last accounting */
    double element_steps; /* sum over the steps taken by this process of the element count */
    int tty_line_open;    /* 1 when a progress line is drawn without newline */
    int tty_drawn;        /* 1 once a progress line has been drawn on the tty */
} run_progress_state;

/* The checkpoints' state (run_ckpt.c). */
typedef struct {
    char *params_eff;    /* the effective parameter file text (checked on restore), malloc'd */
    cdem_snapshot *snap; /* checkpoint buffer (NULL until the first checkpoint) */
    int last_inc;        /* increment of the last periodic checkpoint (0: none yet) */
    int off;             /* 1 when the file layer cannot store checkpoints */
    /* 1 on the steps whose sample reports the forces on boundary elements (the run loop sets
     * it every step); 0: a checkpoint stores those forces as 0 (cdem_ckpt_state_put says why).
     * Stored as "it.boundary_forces" (cdem_integrator_snapshot_put), where the checkpoint
     * layout has it. */
    int boundary_forces;
} run_ckpt_state;

/* Everything a run owns, released by cdem_run_close. */
struct cdem_run_ctx {
    const cdem_params *p;        /* parameters (caller's) */
    const cdem_run_options *opt; /* options (caller's) */
    cdem_model m;                /* derived constants */
    cdem_state s;                /* the elements */
    cdem_assembly_info info;     /* what the assembly generator built */
    cdem_processes procs;        /* the processes the parameters turn on (process.h) */
    cdem_bc bc;                  /* boundary mode */
    cdem_integrator it;          /* time stepper */
    cdem_sediment sed;           /* syn-tectonic sedimentation (disabled when off) */
    cdem_h5_writer *w;           /* output file (NULL: none, staged runs of tests) */
    char *summary;               /* summary + mode view, malloc'd */
    long step;                   /* last completed step */
    long k_def;                  /* deformation steps applied by the mode (settling excluded) */
    int next_inc;                /* number of the next increment to write */
    long next_inc_step;          /* step of increment next_inc on the model schedule */
    long last_written_step;      /* step of the last increment written (-1: none) */
    double base_tol_y;           /* m, wall elements with y below this are the base */
    double wall_mid_x;           /* m, lateral wall elements left of this are the left wall's */
    long removed;                /* escaped elements removed */
    long eroded;                 /* elements removed by erosion, whole run */
    double erosion_y;            /* m, erosion level (INFINITY until the end of equilibration) */
    int finished;                /* 1 once the stop reason is recorded (completed/stopped-early) */
    const char *stop_kind;       /* "completed", "stopped-early", "interrupted" once recorded */
    run_progress_state prog;     /* run_progress.c */
    run_ckpt_state ckpt;         /* run_ckpt.c */
    cdem_governor gov;           /* the thread count in use (governor.h) */
    int gov_started;             /* 1 once the first run_loop call started the governor */
};
typedef struct cdem_run_ctx run_ctx;

/* The phase of step `step` (CDEM_PHASE_*): equilibration up to its last step, then settling
 * while a deposit settles, else deformation. */
static inline int run_phase_of(const run_ctx *r, long step) {
    if (step <= r->m.equil_steps)
        return CDEM_PHASE_EQUILIBRATION;
    return cdem_sediment_settling(&r->sed, step) ? CDEM_PHASE_SETTLING : CDEM_PHASE_DEFORMATION;
}

static inline const char *run_phase_name(int phase) {
    return phase == CDEM_PHASE_EQUILIBRATION ? "equilibration"
           : phase == CDEM_PHASE_DEFORMATION ? "deformation"
                                             : "settling";
}

/* The files call downward only: run.c (the set-up, the loop, cdem_run and cdem_run_resume)
 * calls the other three; run_ckpt.c and run_output.c call run_progress.c; run_progress.c
 * calls none of them. */

/* run_output.c */
/* Erodes (the erosion due before an increment of the deformation phase, through the
 * integrator's removal path, logged), computes the stress when asked, writes increment
 * next_inc of the current step and advances next_inc. */
cdem_status run_write_increment(run_ctx *r, cdem_error *err);
/* Appends the time-series sample of the current step (serial, fixed-order sums). */
cdem_status run_write_sample(run_ctx *r, cdem_error *err);
/* The element count of increment 0 (docs/format.md, "Counting"): free elements and the rest
 * (walls, fault ramps, mylar, footwall display), after the mode has added its own. */
void run_count_kinds(const cdem_state *s, long *n_free, long *n_boundary);
/* The summary text stored in the file (r->summary): the parameters' summary, the mode's view
 * and the solver line. */
cdem_status run_make_summary(run_ctx *r, cdem_error *err);
/* cdem_run_check_memory for the derived model (its elements_estimated): the set-up's, which
 * has derived it already (run_validate.c). */
cdem_status run_check_model_memory(const cdem_model *m, cdem_error *err);

/* run_progress.c */
double run_now(void);
int run_logging(const run_ctx *r);
/* Ends a progress line drawn without a newline (before another log line). */
void run_end_progress_line(run_ctx *r);
/* The progress line; ending NULL: "N s left", else the text that replaces it on the last
 * line ("completed", "stopped early", "interrupted"); force: draw it now, whatever the
 * interval. */
void run_progress_line(run_ctx *r, int force, const char *ending);
void run_progress(run_ctx *r, int force);
/* The last line of a run's log: the file, its size, the increments and how the run ended. */
void run_log_wrote(const run_ctx *r, cdem_status st, int had_writer);
/* "; continue it with: cdem-run --resume FILE" when the file holds a checkpoint to continue
 * from, else why it cannot be continued; "" without a file. */
void run_resume_hint(const run_ctx *r, char *buf, size_t cap);

/* run_ckpt.c */
/* Replaces the state of a set-up run by the checkpoint's. */
cdem_status run_restore(run_ctx *r, const cdem_snapshot *snap, cdem_error *err);
/* Captures the run and stores it in the file as the checkpoint of the increment written last;
 * scheduled = 1: a periodic checkpoint, 0: the checkpoint of a stop. */
cdem_status run_write_checkpoint(run_ctx *r, int scheduled, cdem_error *err);

#endif
