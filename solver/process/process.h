/* process: the physical processes of a run beside the contacts and the boundaries (a viscous
 * substrate such as the salt; docs/solver.md, "Processes"). A process is one folder
 * solver/<id>/ defining one static const cdem_process_ops and its pointer cdem_process_<id>,
 * and one row of common/processes.def; the registry (process_registry.c) is made from the
 * rows, and the run loop (run/run.c), the output (run/run_output.c), the summary
 * (run/summary.c) and the parameter check (run/run_validate.c) loop over the registered
 * processes, so nothing outside a process's folder names it. Checklist (every hook optional
 * unless said):
 *   before the run, from the parameters alone: active (required: whether these parameters
 *   turn it on), rules (its parameter rules, one cdem_rule_add each), describe (its section
 *   of the summary);
 *   set-up, in this order: place (after the assembly is built and the weak interval flagged:
 *   the elements it takes; its log line), configure (after the stepper is set up: its forces
 *   join the step through cdem_viscous_add, integrate.h / viscous.h);
 *   each deformation step: gravity (turns gravity in the model's frame: a tilting margin);
 *   output: increment (before an increment is written: its elements' stress when the run
 *   stores stress; its own measures), sample (a time-series sample: its columns);
 *   the end: finish (its last log line), free.
 * A process's state is its context (state_size bytes, calloc'd): a resumed run sets the same
 * process up again on the same assembly, so what it places and measures is the same; what
 * evolves lives in the element state (the salt's area ratio J) or the stepper (gravity's
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
 * consistency too, as the salt's rules always did). */
void cdem_processes_rules(const cdem_params *p, cdem_rule_log *log);
/* The summary's sections of the processes p turns on. */
void cdem_processes_describe(const cdem_params *p, const cdem_model *m, FILE *out);
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
