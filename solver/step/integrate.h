/* integrate: the time stepper. Velocity Verlet for translational motion of free elements
 * (not wall/fault/footwall/mylar) with viscous damping and the external loads:
 *   v_half = v + dt/(2m) F(t);  x += dt v_half;  [boundary mode moves its elements]
 *   F_c = sum of pair forces at x(t+dt) (pair slots, then per-element CSR sums);
 *   v(t+dt) = (v_half + dt/(2m) (F_c - m g e_y)) / (1 + c dt / (2m))
 * i.e. the damping force -c v(t+dt) is taken implicitly, so the terminal velocity of a
 * falling element is exactly m g / c; F(t+dt) = F_c - m g e_y - c v(t+dt) is stored in
 * state fx, fy (boundary elements: the contact force on them).
 * A step is a short sequence of phases, each in a module of its own: drift
 * (cdem_force_drift, inside the force pass's parallel region when the boundary mode is
 * boundary-only, which then moves first: the two commute exactly), the boundary mode
 * (bc.h), the force pass with the rebuild test (force.h), and at a rebuild the
 * removal of escaping elements (removal.h), the list build (neighbour.h), the pair classes
 * and the surface and edge elements of the loads (loads.h).
 * The integrator owns the neighbour list and contact histories; it never owns the state.
 * Escaping elements (cdem_integrator_enable_escape) are removed at list rebuilds. Nothing
 * allocates in a step except at list rebuilds (geometric growth). Heterogeneity: after each
 * list rebuild the element-element pair classes are refined from layers and flags
 * (cdem_contact_refine). Determinism: bit-identical for any thread count (force.h).
 * With contact damping or a viscous process (viscous.h) a step drifts first, brings the list
 * up to date, adds their forces around the force pass (step_with_viscous in integrate.c).
 * Thread safety: one integrator per run. Units: SI (m, s, kg per metre, N). */
#ifndef CDEM_INTEGRATE_H
#define CDEM_INTEGRATE_H

#include "bc.h"
#include "cdem_error.h"
#include "contact.h"
#include "force.h"
#include "loads.h"
#include "model.h"
#include "neighbour.h"
#include "params.h"
#include "removal.h"
#include "state.h"
#include "viscous.h"

/* Per-element factors of the two half kicks, derived from mass, dt and damping at every list
 * build (so masses may change only between builds: at set-up, or by appending elements):
 * drift[i] = (dt/2) / m, finish[i] = 1 / (m + c dt/2); the same values the kicks would divide
 * out each step, one division per element and build instead of two per element and step.
 * Valid for build == nb.n_builds, n == the element count, dt and c those of the step;
 * scratch, not state (never serialised). */
typedef struct {
    double *drift, *finish;
    size_t cap; /* capacity of drift and finish */
    long build;
    size_t n;
    double dt;
    double c; /* the damping the factors were derived for */
} cdem_kick_factors;

typedef struct {
    double dt;             /* s, time step, > 0 */
    double damping;        /* N s/m, viscous coefficient c of the model, >= 0 */
    double damping_factor; /* multiplier of c on the current step, >= 0 (1 after init; the
                              run loop sets physics.deformation_damping on deformation
                              steps): cdem_integrator_damping */
    cdem_contact_law law;  /* contact law and materials */
    cdem_neighbour nb;     /* pair list with histories and force slots */
    long step;             /* steps taken so far */
    long par_min;          /* loops over at most this many items run on one thread (>= 0);
                              results are bit-identical either way */
    /* 1 on the steps of the equilibration (the packing phase), 0 afterwards: selects the law
     * in force (cdem_contact_law_phase: settling friction, cohesion of forming contacts).
     * Set by the run loop (1 from set-up to the last equilibration step); 0 after init: the
     * material as given. */
    int equilibrating;
    /* unstable-motion guard (0 = off; the run loop sets it): after each step,
     * unstable_index is the lowest index whose element moved more than its radius in the
     * step's velocity (|v| dt > r), or -1; found in the force pass's element loop */
    int unstable_guard;
    long unstable_index;

    cdem_kick_factors kick; /* the half kicks' per-element factors */
    cdem_force force;       /* the force pass's decomposition (force.h) */
    cdem_loads loads;       /* gravity, overburden, confinement (loads.h) */
    cdem_removal removal;   /* escapes, erosion, the mode's removals and their record
                               (removal.h) */
    cdem_viscous viscous;   /* contact damping and the processes' forces (viscous.h; off:
                               nothing changes) */
    /* may be NULL (gravity as the mode sets it): on every deformation step k >= 1, after the
     * mode's gravity hook, turns gravity (*gx, *gy: the mode's, else the model's direction) in
     * the model's frame and returns 1, or returns 0 to leave it; the run sets it to its
     * processes' (process.h, the gravity hook: a tilting margin) */
    int (*gravity_turn)(const void *ctx, long k, double *gx, double *gy);
    const void *gravity_turn_ctx;
} cdem_integrator;

/* The viscous coefficient in force on the current step, N s/m: damping x damping_factor. */
static inline double cdem_integrator_damping(const cdem_integrator *it) {
    return it->damping * it->damping_factor;
}

/* Sets up the stepper from the model constants (dt, damping, gravity, kn, ks, max radius)
 * and material parameters. skin = 0.25 x the smallest radius. */
cdem_status cdem_integrator_init(cdem_integrator *it, const cdem_params *p, const cdem_model *m,
                                 cdem_error *err);
void cdem_integrator_free(cdem_integrator *it);

/* Enables removal of escaping elements; the x bounds are the current extreme lateral wall
 * positions (re-read at each rebuild), ymin the lowest base wall. */
void cdem_integrator_enable_escape(cdem_integrator *it);

/* Computes the forces of the current positions (first call before stepping; also builds
 * the pair list). Does not move anything. */
cdem_status cdem_integrator_prime(cdem_integrator *it, cdem_state *s, cdem_error *err);

/* One time step. bc (may be NULL: walls still) is applied with deformation step k and
 * increment du: before the drift when it moves boundary elements only (the two commute
 * exactly), else after it. Fails with CDEM_ERR_NUMERIC naming the element and step
 * when a position becomes NaN/Inf. */
cdem_status cdem_integrator_step(cdem_integrator *it, cdem_state *s, cdem_bc *bc, long k, double du,
                                 cdem_error *err);

/* The overburden and the confining pressure are set on the loads (cdem_loads_set_overburden,
 * cdem_loads_set_confining with it->step) after init; the surface and edge elements are found
 * again at every list rebuild. */

/* Re-derives the material class of every pair from the current layers and flags (call
 * after layers change, e.g. at the end of equilibration). */
void cdem_integrator_classify(cdem_integrator *it, const cdem_state *s);

/* Erosion: removes every free element whose centre is above ymax (m) through the same
 * path as escaping elements (ids in removal.removed_ids, count in removal.n_removed_last and
 * *count), rebuilds the list and recomputes the forces of the current positions (no
 * tangential increment, velocities unchanged). */
cdem_status cdem_integrator_erode(cdem_integrator *it, cdem_state *s, double ymax, long *count,
                                  cdem_error *err);

/* Start of deformation, once before deformation step 1: runs the mode's begin_deformation
 * hook and removes the elements it marks (any kind, walls included) through the same path as
 * escaping elements: state compacted, histories of the remaining pairs kept, forces
 * re-evaluated; their ids are in removal.removed_ids / n_removed_last (not counted in
 * removal.n_removed, which counts escapes and erosion). bc NULL: nothing. *n_removed = number
 * removed. */
cdem_status cdem_integrator_begin_deformation(cdem_integrator *it, cdem_state *s, cdem_bc *bc,
                                              size_t *n_removed, cdem_error *err);

/* End of equilibration: every touching pair becomes cohesive (granular) or bonded (bonded
 * model), except flexural-slip pairs (CDEM_CLASS_SLIP); with cohesive_contacts = initial only
 * the touching pairs still marked initial (cdem_integrator_mark_initial). Returns the number of
 * pairs so marked. */
long cdem_integrator_make_cohesive(cdem_integrator *it, const cdem_state *s);

/* cohesive_contacts = initial (granular), before the first step of a fresh run: marks every
 * pair of the built assembly in contact (r < R (1 + 1e-9): its exact tangencies count) as an
 * initial contact (CDEM_PAIR_INITIAL); the mark is lost when the pair separates, and at the
 * end of equilibration only the marked touching pairs become cohesive. Returns the pairs
 * marked (0 for the other rules). Needs the pair list of s (after prime). */
long cdem_integrator_mark_initial(cdem_integrator *it, const cdem_state *s);

/* Counts touching pairs and intact bonds / cohesive contacts. */
void cdem_integrator_count(const cdem_integrator *it, long *contacts, long *bonds);

/* Checkpoints (checkpoint.h): the stepper's evolving fields under "it." (step, escape
 * bounds, removal count, surface/edge counts, confining ramp factor and edge midpoint, and
 * the run loop's boundary_forces flag, stored here for the layout's sake: see run_ckpt.c),
 * its configuration (dt, damping, gravity, overburden, confining pressure; checked on
 * restore), the contact law (cdem_contact_snapshot_put) and the pair list with the contact
 * histories (cdem_neighbour_snapshot_put). Scratch (kick factors, force decomposition, keep,
 * removed_ids, the loads' column scratch) is not stored. */
cdem_status cdem_integrator_snapshot_put(const cdem_integrator *it, int boundary_forces,
                                         cdem_snapshot *snap, cdem_error *err);
/* Restores into it, set up as for the original run (init, the loads' overburden and
 * confinement, enable_escape): CDEM_ERR_CONFLICT when its configuration differs from the
 * stored one. s is the already restored state; *boundary_forces = the stored flag. */
cdem_status cdem_integrator_snapshot_get(cdem_integrator *it, const cdem_snapshot *snap,
                                         const cdem_state *s, int *boundary_forces,
                                         cdem_error *err);

#endif
