/* sediment: syn-tectonic sedimentation (manual item 15, paper's Theory "Syn-sedimentation").
 * Every sediment_steps run steps after equilibration a deposit of new free elements fills the
 * space between the current surface and sea level = ymax + (step - equil_steps) x du x factor
 * (ymax: highest free-element top at the end of equilibration). Deposition is geometric: discs
 * of the four model radii (number fractions 4:3:2:1) are dropped vertically at random x onto
 * the pile and rest on the highest element they meet; a disc is kept when it has a support and
 * its centre is below sea level. Kept discs never overlap (by construction; checked to within
 * CDEM_SEDIMENT_OVERLAP_TOL x radius). Then the deposit settles for settling_steps (walls
 * still; the run loop does not count those steps as deformation), and at its end the touching
 * pairs involving the deposit become cohesive/bonded.
 * Ownership: cdem_sediment owns its gsl_rng (seeded from params seed) and scratch (grown only
 * at deposit events, never in a time step); _free accepts NULL. Thread safety: one per run.
 * Units: m, kg per metre, time steps. */
#ifndef CDEM_SEDIMENT_H
#define CDEM_SEDIMENT_H

#include "cdem_error.h"
#include "integrate.h"
#include "model.h"
#include "params.h"
#include "state.h"

#include <gsl/gsl_rng.h>
#include <stdint.h>

/* Largest overlap allowed between a deposited disc and any element, as a fraction of the
 * deposited radius (deposition is overlap-free; this only absorbs rounding). */
#define CDEM_SEDIMENT_OVERLAP_TOL 1e-9

typedef struct {
    int enabled;                   /* 0/1: params surface.sedimentation */
    gsl_rng *rng;                  /* mt19937 seeded with params seed ^ 0x5ed1, owned */
    double radius[CDEM_NUM_RADII]; /* m, model radii, ascending */
    double mass[CDEM_NUM_RADII];   /* kg/m, mass of each radius class */
    double du;                     /* m, boundary displacement per step, > 0 */
    double factor;                 /* sea-level rise factor 0..1 */
    long equil_steps;              /* last equilibration step, >= 0 */
    long total_steps;              /* last step of the run */
    long sediment_steps;           /* run steps between deposits, >= 1 */
    long settling_steps;           /* steps of settling after a deposit, >= 0 */
    double ymax0;                  /* m, sea level at the end of equilibration (NaN before) */
    int events;                    /* deposits made so far, >= 0 */
    long event_step;               /* step of the last deposit (-1: none) */
    long settle_end;               /* last settling step of the last deposit (-1: none) */
    int32_t settling_layer;        /* layer of the deposit settling now, 0: none */
    long n_deposited;              /* elements deposited in the whole run */
    /* scratch of a deposit (column grid of width 2 x max radius, common/grid.h) */
    int32_t *col_of;    /* column of each element present (-1: left out) */
    int32_t *col_start; /* CSR start of each column, ncol + 1 */
    int32_t *col_items; /* element indices by column */
    int32_t *col_head;  /* first new disc of each column (-1: none) */
    int32_t *next_new;  /* next new disc in the same column, by (index - n0) */
    size_t colcap;      /* capacity of col_start/col_head (columns + 1) */
    size_t itemcap;     /* capacity of col_items */
    size_t keycap;      /* capacity of col_of */
    size_t newcap;      /* capacity of next_new */
} cdem_sediment;

/* The growth strata's parameter rule (a cdem_params_rules of cdem_params_validate): with
 * sedimentation on, a deposit's settling (0.2 x equilibration) must end before the next
 * deposit is due (30 x display_interval of boundary displacement); the message gives the
 * display_interval and the equilibration that would do. */
void cdem_sediment_rules(const cdem_params *p, cdem_rule_log *log);

/* Sets up from the parameters and model; p->sedimentation = 0 gives a disabled context
 * (every query answers "nothing", sea level NaN). Fails with CDEM_ERR_RANGE when the model
 * step counts or radii are unusable, CDEM_ERR_NOMEM when the RNG cannot be allocated. */
cdem_status cdem_sediment_init(cdem_sediment *sd, const cdem_params *p, const cdem_model *m,
                               cdem_error *err);
void cdem_sediment_free(cdem_sediment *sd);

/* End of equilibration: records ymax (highest top y + r of a free element). */
void cdem_sediment_begin(cdem_sediment *sd, const cdem_state *s);

/* Sea level after run step `step` (m); NaN when disabled or before the end of equilibration. */
double cdem_sediment_sea_level(const cdem_sediment *sd, long step);

/* 1 when step is a settling step of the last deposit (boundaries still), else 0. */
int cdem_sediment_settling(const cdem_sediment *sd, long step);

/* 1 when a deposit is due after step: enabled, step - equil_steps a positive multiple of
 * sediment_steps, no settling in progress, and the settling fits before total_steps. */
int cdem_sediment_due(const cdem_sediment *sd, long step);

/* Deposits discs below sea_level onto the free elements of s (appended with new ids, layer,
 * CDEM_FLAG_GROWTH, born). *added receives the count. Does not touch existing elements.
 * Fails with CDEM_ERR_RANGE when sea_level is not finite or there are no free elements,
 * CDEM_ERR_NOMEM on allocation failure. */
cdem_status cdem_sediment_deposit(cdem_sediment *sd, cdem_state *s, double sea_level, int32_t layer,
                                  int32_t born, long *added, cdem_error *err);

/* A whole deposit event after run step `step`: layer 25 + events, deposit, recompute the
 * forces (cdem_integrator_prime) and start settling. */
cdem_status cdem_sediment_event(cdem_sediment *sd, cdem_integrator *it, cdem_state *s, long step,
                                int32_t born, long *added, cdem_error *err);

/* Makes every touching pair with an element of growth layer `layer` cohesive (granular) or
 * bonded (bonded model), except flexural-slip pairs; returns the number of pairs marked. */
long cdem_sediment_make_cohesive(cdem_integrator *it, const cdem_state *s, int32_t layer);

/* Call after each run step: when step ends the settling of the last deposit, makes its
 * touching pairs cohesive (returned count, else 0) and clears settling_layer. */
long cdem_sediment_after_step(cdem_sediment *sd, cdem_integrator *it, const cdem_state *s,
                              long step);

/* Checkpoints (checkpoint.h): under "sed." the evolving fields (sea-level reference ymax0,
 * events, event_step, settle_end, settling_layer, n_deposited) and the RNG state (the raw
 * mt19937 state bytes and the generator's name); a disabled context stores only "enabled".
 * _get restores into a context initialised from the same parameters (CDEM_ERR_CONFLICT
 * when the stored one was enabled differently or used another generator). */
cdem_status cdem_sediment_snapshot_put(const cdem_sediment *sd, cdem_snapshot *snap,
                                       cdem_error *err);
cdem_status cdem_sediment_snapshot_get(cdem_sediment *sd, const cdem_snapshot *snap,
                                       cdem_error *err);

#endif
