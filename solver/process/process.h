/* process: the physical processes of a run beside the contacts and the boundaries (e.g. a
 * viscous substrate; docs/solver.md, "Processes"). A process is one folder
 * solver/<id>/ defining one static const cdem_process_ops and its pointer cdem_process_<id>,
 * and one row of common/processes.def; the registry (process_registry.c) is made from the
 * rows, and the run loop (run/run.c), the output (run/run_output.c), the summary
 * (run/summary.c) and the parameter check (run/run_validate.c) loop over the registered
 * processes, so nothing outside a process's folder names it. Checklist (every hook optional
 * unless said):
 *   before the run, from the parameters alone: active (required: whether these parameters
 *   turn it on), rules (its parameter rules, one cdem_rule_add each), describe (its section
 *   of the summary), time_scale (the clock's map to geological time, if it has one: the
 *   others' summaries quote their times in it);
 *   set-up, in this order: place (after the assembly is built and the weak interval flagged:
 *   the elements it takes; its log line), configure (after the stepper is set up: its forces
 *   join the step through cdem_viscous_add, integrate.h / viscous.h);
 *   each deformation step: gravity (turns gravity in the model's frame: a tilting margin);
 *   output: increment (before an increment is written: its elements' stress when the run
 *   stores stress; its own measures), sample (a time-series sample: its columns);
 *   the end: finish (its last log line), free.
 * What the common layer must know of a process is declared in its file
 * common/processes/<id>.h (processes.def says how), where both programs and the layers below
 * this one read it: its parameters; CDEM_PROCESS_ELEMENTS, the density of elements of its own,
 * whose smallest mass the model's time step must know before any process exists
 * (base/model.c, which names the lightest in the summary); CDEM_PROCESS_SERIES, its columns of
 * the time series (h5format.h: the writer, the reader and the analysis take them from there;
 * its sample hook fills them, NaN while it is off). Its elements' flag (flag, below) is also
 * in state.h's CDEM_FLAGS_PROCESS, so that the pair list leaves their pairs to it.
 * A process derives its own constants from the parameters and the model (e.g. in place, the
 * first hook with a context; describe and rules derive them again).
 * A process's state is its context (state_size bytes, calloc'd): a resumed run sets the same
 * process up again on the same assembly, so what it places and measures is the same; what
 * evolves lives in the element state (e.g. the area ratio J) or the stepper (gravity's
 * direction) and is checkpointed with it.
 * Ownership: cdem_processes owns the contexts. Thread safety: one per run. Units: SI. */
#ifndef CDEM_PROCESS_H
#define CDEM_PROCESS_H

#include "cdem_error.h"
#include "h5format.h"
#include "integrate.h"
#include "model.h"
#include "params.h"
#include "state.h"

#include <stdint.h>
#include <stdio.h>

typedef struct {
    const char *word;  /* its name (processes.def), for messages */
    size_t state_size; /* bytes of its context, > 0 */
    uint32_t flag;     /* the element flag its elements carry (state.h), 0: none */
    int (*active)(const cdem_params *p);
    void (*rules)(const cdem_params *p, cdem_rule_log *log);
    void (*describe)(const cdem_params *p, const cdem_model *m, FILE *out);
    /* geological seconds per model second when the process maps the run's clock to geological
     * time (a viscous substrate of a geological viscosity does), else 0: what the other
     * processes' summaries quote their times in (cdem_processes_time_scale) */
    double (*time_scale)(const cdem_params *p, const cdem_model *m);
    /* log: the run's log, or NULL (quiet) */
    cdem_status (*place)(void *ctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                         FILE *log, cdem_error *err);
    cdem_status (*configure)(void *ctx, const cdem_params *p, const cdem_model *m,
                             cdem_integrator *it, cdem_error *err);
    /* deformation step k >= 1, after the boundary mode's gravity hook (bc.h): turns gravity's
     * acceleration (*gx, *gy, m/s^2, the model's frame; the mode's, or the model's direction
     * when the mode has no hook) in place. A function of k and the context only, so that a
     * resumed run turns it alike; what it sets holds through the steps that are not
     * deformation steps, and the stepper's checkpoint keeps it */
    void (*gravity)(const void *ctx, long k, double *gx, double *gy);
    void (*increment)(void *ctx, cdem_state *s);
    void (*sample)(const void *ctx, const cdem_state *s, cdem_series_sample *q);
    void (*finish)(const void *ctx, FILE *log);
    void (*free)(void *ctx);
} cdem_process_ops;

/* The processes a run's parameters turn on, in registry order. */
typedef struct {
    int n;
    const cdem_process_ops *ops[8];
    void *ctx[8];
} cdem_processes;

/* Every registered process's parameter rules (a process that is off checks its own keys'
 * consistency too). */
void cdem_processes_rules(const cdem_params *p, cdem_rule_log *log);
/* The summary's sections of the processes p turns on. */
void cdem_processes_describe(const cdem_params *p, const cdem_model *m, FILE *out);
/* The geological seconds per model second of the first process p turns on that maps the
 * clock (its time_scale hook), with its word in *word; 0 (and *word NULL) when none does. */
double cdem_processes_time_scale(const cdem_params *p, const cdem_model *m, const char **word);
/* The processes p turns on, their contexts allocated (nothing placed yet). */
cdem_status cdem_processes_init(cdem_processes *ps, const cdem_params *p, cdem_error *err);
/* Adds a process whatever the parameters say, its context allocated (the tests' fixtures,
 * which no parameter turns on). */
cdem_status cdem_processes_add(cdem_processes *ps, const cdem_process_ops *ops, cdem_error *err);
cdem_status cdem_processes_place(cdem_processes *ps, const cdem_params *p, const cdem_model *m,
                                 cdem_state *s, FILE *log, cdem_error *err);
cdem_status cdem_processes_configure(cdem_processes *ps, const cdem_params *p, const cdem_model *m,
                                     cdem_integrator *it, cdem_error *err);
/* Gravity of deformation step k turned by each process's gravity hook in order: 1 when one
 * has the hook (*gx, *gy then hold the result), 0 when none has (untouched). */
int cdem_processes_gravity(const cdem_processes *ps, long k, double *gx, double *gy);
void cdem_processes_increment(cdem_processes *ps, cdem_state *s);
void cdem_processes_sample(const cdem_processes *ps, const cdem_state *s, cdem_series_sample *q);
void cdem_processes_finish(const cdem_processes *ps, FILE *log);
void cdem_processes_free(cdem_processes *ps);

/* The processes, one pointer each (solver/<id>/), by the rows of common/processes.def. */
#define CDEM_PROCESS(ID, id, word) extern const cdem_process_ops *const cdem_process_##id;
#define CDEM_TEST_PROCESS          CDEM_PROCESS
#include "processes.def"
#undef CDEM_PROCESS
#undef CDEM_TEST_PROCESS

#endif
