/* integrate: the time stepper. Velocity Verlet for translational motion of free elements
 * (not wall/fault/footwall/mylar) with viscous damping and gravity:
 *   v_half = v + dt/(2m) F(t);  x += dt v_half;  [boundary mode moves its elements]
 *   F_c = sum of pair forces at x(t+dt) (pair slots, then per-element CSR sums);
 *   v(t+dt) = (v_half + dt/(2m) (F_c - m g e_y)) / (1 + c dt / (2m))
 * i.e. the damping force -c v(t+dt) is taken implicitly, so the terminal velocity of a
 * falling element is exactly m g / c; F(t+dt) = F_c - m g e_y - c v(t+dt) is stored in
 * state fx, fy (boundary elements: the contact force on them, for reports, when
 * boundary_forces is set).
 * Determinism: every element sums its pair forces in ascending pair order (a scatter in
 * slot order; threads own element chunks, cross-chunk pairs are subtracted first): bit-
 * identical for any thread count. The integrator owns the neighbour list and contact histories; it
 * never owns the state. Escaping elements (cdem_integrator_enable_escape) are removed at list
 * rebuilds. Nothing allocates in a step except at list rebuilds (geometric growth). Heterogeneity:
 * after each list rebuild the element-element pair classes are refined from layers and flags
 * (cdem_contact_refine). Overburden: at each rebuild the highest free element of each column (width
 * 2 x max radius) is flagged CDEM_FLAG_SURFACE and carries a constant force -p x column width in y
 * until the next rebuild. Confining pressure: the same sideways on the band edges
 * (cdem_integrator_find_edges), ramped during equilibration. Thread safety: one integrator per run.
 * Units: SI (m, s, kg per metre, N). */
#ifndef CDEM_INTEGRATE_H
#define CDEM_INTEGRATE_H

#include "bc.h"
#include "cdem_error.h"
#include "contact.h"
#include "model.h"
#include "neighbour.h"
#include "params.h"
#include "state.h"

/* Largest number of element chunks (threads) of the force pass. */
#define CDEM_MAX_CHUNKS 64

typedef struct {
    double dt;             /* s, time step, > 0 */
    double damping;        /* N s/m, viscous coefficient c of the model, >= 0 */
    double damping_factor; /* multiplier of c on the current step, >= 0 (1 after init; the
                              run loop sets physics.deformation_damping on deformation
                              steps): cdem_integrator_damping */
    double gravity;        /* m/s^2, applied in -y, >= 0 */
    cdem_contact_law law;  /* contact law and materials */
    cdem_neighbour nb;     /* pair list with histories and force slots */
    long step;             /* steps taken so far */
    int boundary_forces;   /* 0/1, kept for the callers: the force pass now sums the contact
                              force on boundary elements (state fx, fy) every step, as it
                              costs nothing extra in the scatter; 1 = default */
    long par_min;          /* loops over fewer items than this run on one thread (>= 0);
                              results are bit-identical either way */

    /* force pass decomposition (scratch derived from the pair list, not state: rebuilt
     * whenever the list or the thread count changes; never serialised). Chunk c owns the
     * elements chunk_elem[c]..chunk_elem[c+1]-1 and their pi ranges; a cross pair has its
     * pj in a later chunk than its pi; every pair is evaluated by the chunk of its pj, and
     * the chunks are cut by estimated work (pairs by pj, elements) scaled by the shares
     * below. */
    int nchunk;                              /* chunks of the last force pass, 1..CDEM_MAX_CHUNKS */
    long chunk_build;                        /* nb.n_builds the chunks were derived for */
    size_t chunk_n;                          /* element count the chunks were derived for */
    int32_t chunk_elem[CDEM_MAX_CHUNKS + 1]; /* first element of each chunk; [nchunk] = n */
    int32_t cross_start[CDEM_MAX_CHUNKS + 1]; /* cross pairs into chunk c: cross[cross_start[c]
                                                 .. cross_start[c+1]-1], ascending slots */
    int32_t *cross;                           /* pair slots of the cross pairs (crosscap) */
    size_t crosscap;                          /* capacity of cross, >= nb.pcap after builds */
    /* progress of each chunk's cross-pair evaluation in the current threaded pass: every
     * cross pair of chunk c at a slot below cross_done[c].slot is evaluated (atomic; reset to
     * 0 before every pass, raised in steps as the chunk's thread goes through its ascending
     * list, INT32_MAX when done). An earlier chunk meeting a cross pair at slot p waits only
     * until every later chunk is past p. One cache line each: the owner writes while the
     * others read. */
    struct {
        _Atomic int32_t slot;
        char pad[64 - sizeof(int32_t)];
    } cross_done[CDEM_MAX_CHUNKS];
    /* load balance: chunk c is cut to receive chunk_share[c] of the estimated work
     * (make_chunks); chunk_time[c] is the running mean of the seconds its thread spent in
     * the force passes since the last cut. At every cut the shares move toward equal
     * times, so a thread on a slower or busier core gets less to do. Any cut gives the same
     * bits (the sums do not depend on it), so the shares only change the speed. */
    int share_n;                         /* nchunk the shares are for (0: none yet) */
    double chunk_share[CDEM_MAX_CHUNKS]; /* fractions of the work, sum 1 */
    double chunk_time[CDEM_MAX_CHUNKS];  /* s per force pass, running mean (0: none yet) */
    /* per-element factors of the two half kicks, derived from mass, dt and damping at every
     * list build (so masses may change only between builds: at set-up, or by appending
     * elements): kick_drift[i] = (dt/2) / m, kick_finish[i] = 1 / (m + c dt/2); the same
     * values the kicks would divide out each step, one division per element and build
     * instead of two per element and step. Valid for kick_build == nb.n_builds, kick_n ==
     * the element count and kick_dt == dt; scratch, not state (never serialised). */
    double *kick_drift, *kick_finish;
    uint32_t *elem_work; /* scratch of make_chunks: each element's work (kickcap) */
    size_t kickcap;      /* capacity of kick_drift, kick_finish and elem_work */
    long kick_build;
    size_t kick_n;
    double kick_dt;
    double kick_c; /* the damping the kick factors were derived for */
    /* unstable-motion guard (0 = off; the run loop sets it): after each step,
     * unstable_index is the lowest index whose element moved more than its radius in the
     * step's velocity (|v| dt > r), or -1; found in the force pass's element loop */
    int unstable_guard;
    long unstable_index;

    /* escape bounds (enabled when bounds_set): removed when x < xmin - r, x > xmax + r or
     * y < ymin - max_radius; x bounds follow the moving lateral walls */
    int bounds_set;                               /* 0/1 */
    double escape_xmin, escape_xmax, escape_ymin; /* m */
    double max_radius;                            /* m, largest radius of the model */
    unsigned char *keep;                          /* per-element scratch for removal (ncap) */
    size_t keepcap;                               /* capacity of keep */
    long n_removed;                               /* elements removed so far */
    int32_t *removed_ids;  /* ids removed at the last rebuild (n_removed_last of them) */
    size_t n_removed_last; /* count at the last rebuild */
    size_t removed_cap;    /* capacity of removed_ids */

    /* overburden (enabled when overburden_force > 0) */
    double overburden_pressure; /* N/m, vertical pressure on the top surface, >= 0 */
    double column_width;        /* m, surface-search column width = 2 x max_radius, > 0 */
    double overburden_force;    /* N, force on each surface element = pressure x column_width */
    long n_surface;             /* surface elements flagged at the last rebuild */
    size_t *col_top;            /* per-column scratch: the surface element (colcap) */
    size_t colcap;              /* capacity of col_top */

    /* confining pressure on the free side edges (enabled when confining_pressure > 0) */
    double confining_pressure;  /* N/m, full lateral pressure, >= 0 */
    long confining_equil;       /* steps of equilibration: ramp 0 at half of it, 1 at its end */
    double confining_factor;    /* ramp factor of the current step, 0..1 */
    double edge_x_mid;          /* m, edge elements left of this are pushed in +x, others -x */
    long n_edge;                /* edge elements flagged at the last rebuild */
    int32_t *band_lo, *band_hi; /* per-band scratch: leftmost / rightmost element (bandcap) */
    size_t bandcap;             /* capacity of band_lo, band_hi */

    /* 1 on the steps of the equilibration (the packing phase), 0 afterwards: selects the law
     * in force (cdem_contact_law_phase: settling friction, cohesion of forming contacts).
     * Set by the run loop (1 from set-up to the last equilibration step); 0 after init: the
     * material as given. */
    int equilibrating;
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
 * increment du after the drift. Fails with CDEM_ERR_NUMERIC naming the element and step
 * when a position becomes NaN/Inf. */
cdem_status cdem_integrator_step(cdem_integrator *it, cdem_state *s, cdem_bc *bc, long k, double du,
                                 cdem_error *err);

/* Enables the overburden: pressure in N/m (>= 0, finite) on the top surface. Surface
 * elements are found again at every list rebuild. Fails with CDEM_ERR_RANGE naming
 * surface.overburden_pressure when the value is negative or not finite. */
cdem_status cdem_integrator_set_overburden(cdem_integrator *it, double pressure, cdem_error *err);

/* Flags the surface elements now (clears CDEM_FLAG_SURFACE elsewhere): in columns of width
 * column_width from the leftmost free element, the free element with the highest centre
 * (common/surface.h, CDEM_SURFACE_BY_CENTRE). Called at every rebuild when the overburden is on;
 * public for tests and views. */
cdem_status cdem_integrator_find_surface(cdem_integrator *it, cdem_state *s, cdem_error *err);

/* Enables the confining pressure: pressure in N/m (>= 0, finite; 0 disables) on the free side
 * edges, ramped by cdem_bc_confining_ramp(step, equil_steps). Fails with CDEM_ERR_RANGE naming
 * boundary.confining_pressure when the value is negative or not finite. */
cdem_status cdem_integrator_set_confining(cdem_integrator *it, double pressure, long equil_steps,
                                          cdem_error *err);

/* Flags the edge elements now (clears CDEM_FLAG_BIAXIAL_EDGE elsewhere): per band of height
 * column_width from the lowest free centre, the leftmost and rightmost free element; sets
 * edge_x_mid to the middle of the free span. Called at every rebuild when the confining
 * pressure is on; public for tests. */
cdem_status cdem_integrator_find_edges(cdem_integrator *it, cdem_state *s, cdem_error *err);

/* Re-derives the material class of every pair from the current layers and flags (call
 * after layers change, e.g. at the end of equilibration). */
void cdem_integrator_classify(cdem_integrator *it, const cdem_state *s);

/* Erosion: removes every free element whose centre is above ymax (m) through the same
 * path as escaping elements (ids in removed_ids, count in n_removed_last and *count),
 * rebuilds the list and recomputes the forces of the current positions (no tangential
 * increment, velocities unchanged). */
cdem_status cdem_integrator_erode(cdem_integrator *it, cdem_state *s, double ymax, long *count,
                                  cdem_error *err);

/* Start of deformation, once before deformation step 1: runs the mode's begin_deformation
 * hook and removes the elements it marks (any kind, walls included) through the same path as
 * escaping elements: state compacted, histories of the remaining pairs kept, forces
 * re-evaluated; their ids are in removed_ids / n_removed_last (not counted in n_removed,
 * which counts escapes). bc NULL: nothing. *n_removed = number removed. */
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
 * bounds, removal count, surface/edge counts, confining ramp factor and edge midpoint,
 * boundary_forces), its configuration (dt, damping, gravity, overburden, confining pressure;
 * checked on restore), the contact law (cdem_contact_snapshot_put) and the pair list with
 * the contact histories (cdem_neighbour_snapshot_put). Scratch (keep, removed_ids, col_top,
 * band_lo/hi) is not stored. */
cdem_status cdem_integrator_snapshot_put(const cdem_integrator *it, cdem_snapshot *snap,
                                         cdem_error *err);
/* Restores into it, set up as for the original run (init, set_overburden, set_confining,
 * enable_escape): CDEM_ERR_CONFLICT when its configuration differs from the stored one. s is
 * the already restored state. */
cdem_status cdem_integrator_snapshot_get(cdem_integrator *it, const cdem_snapshot *snap,
                                         const cdem_state *s, cdem_error *err);

#endif
