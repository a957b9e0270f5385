/* integrate: see integrate.h. The step is a sequence of named phases:
 *   drift           first half kick and drift of the free elements (over the force pass's
 *                   chunks: each thread moves the elements whose forces it computes next)
 *   begin step      the step counter and the confining ramp (loads.h)
 *   boundary mode   cdem_bc_apply moves the mode's elements
 *   force pass      the rebuild test, the pair forces and the second half kick (force.h)
 * and when the test says the list is stale: the NaN check, the rebuild (escapes found and
 * removed, the list built, pair classes, surface and edge elements) and the force pass again.
 * When the boundary mode touches boundary elements only (every mode but the biaxial servo,
 * cdem_bc_apply_is_boundary_only), it commutes exactly with the drift, which moves free
 * elements only: the mode is applied first and the drift runs inside the force pass's
 * parallel region (one region and one barrier a step). Otherwise the drift has a region of
 * its own before the mode (two regions and one barrier). Either order gives the same bits. */
#include "integrate.h"

#include "checkpoint.h"
#include "parallel.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Rebuilds between re-sorts of the state into cell order. */
#define RESORT_EVERY 20

cdem_status cdem_integrator_init(cdem_integrator *it, const cdem_params *p, const cdem_model *m,
                                 cdem_error *err) {
    memset(it, 0, sizeof *it);
    if (!(m->dt > 0.0) || !isfinite(m->dt))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "integrator: model dt = %g s: must be > 0", m->dt);
    if (!(m->damping >= 0.0) || !isfinite(m->damping))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "integrator: model damping = %g N s/m: must be >= 0",
                         m->damping);
    if (!(m->gravity >= 0.0) || !isfinite(m->gravity))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "integrator: model gravity = %g m/s^2: must be >= 0",
                         m->gravity);
    if (!(m->radius[0] > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: smallest radius = %g m: must be > 0 (skin is 0.25 of it)",
                         m->radius[0]);
    it->par_min = CDEM_PAR_MIN; /* parallel.h says why */
    it->damping_factor = 1.0;
    it->unstable_index = -1;
    it->dt = m->dt;
    it->damping = m->damping;
    const double max_radius = m->max_radius > 0.0 ? m->max_radius : m->radius[CDEM_NUM_RADII - 1];
    cdem_loads_init(&it->loads, m->gravity, m->mode.gravity_tilt, max_radius);
    cdem_removal_init(&it->removal, max_radius);
    CDEM_TRY(cdem_contact_law_init(&it->law, p, m->kn, m->ks, err));
    it->force.law_scalar_only = !cdem_force_law_vectorised(it->law.granular);
    CDEM_TRY(cdem_neighbour_init(&it->nb, 0.25 * m->radius[0], 1.0 + it->law.max_breaking_strain,
                                 RESORT_EVERY, err));
    CDEM_TRY(cdem_neighbour_set_slots(&it->nb, it->law.slot_count, err)); /* the law's history */
    cdem_viscous_init(&it->viscous, m);
    return CDEM_OK;
}

void cdem_integrator_free(cdem_integrator *it) {
    if (!it)
        return;
    cdem_neighbour_free(&it->nb);
    cdem_force_free(&it->force);
    cdem_loads_free(&it->loads);
    cdem_removal_free(&it->removal);
    cdem_viscous_free(&it->viscous);
    free(it->kick.drift);
    free(it->kick.finish);
    memset(it, 0, sizeof *it);
}

void cdem_integrator_enable_escape(cdem_integrator *it) {
    it->removal.bounds_set = 1;
}

/* Grows the kick factors to n elements (after a list build, outside the step's hot loops). */
static cdem_status reserve_kick(cdem_kick_factors *k, size_t n, cdem_error *err) {
    if (k->cap >= n)
        return CDEM_OK;
    const size_t c = n + n / 2 + 16;
    double *a = realloc(k->drift, c * sizeof *a);
    if (a)
        k->drift = a;
    double *b = a ? realloc(k->finish, c * sizeof *b) : NULL;
    if (!b)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu elements)", c);
    k->finish = b;
    k->cap = c;
    return CDEM_OK;
}

/* The kick factors for the current masses, dt and damping (integrate.h), when stale. The
 * expressions are those the kicks used to evaluate every step, so the bits are the same.
 * Returns 0 when they cannot be had without allocating (elements appended since the last
 * build): the kicks then divide as before. */
static int update_kick(cdem_integrator *it, const cdem_state *s) {
    cdem_kick_factors *k = &it->kick;
    if (k->cap < s->n)
        return 0;
    const double c = cdem_integrator_damping(it);
    if (k->build == it->nb.n_builds && k->n == s->n && k->dt == it->dt && k->c == c)
        return 1;
    const double hdt = 0.5 * it->dt;
    const long n = (long)s->n;
    const double *restrict mass = s->mass;
    double *restrict kd = k->drift, *restrict kf = k->finish;
#pragma omp parallel for schedule(static) if (n > it->par_min)
    for (long i = 0; i < n; i++) {
        kd[i] = hdt / mass[i];
        kf[i] = 1.0 / (mass[i] + c * hdt);
    }
    k->build = it->nb.n_builds;
    k->n = s->n;
    k->dt = it->dt;
    k->c = c;
    return 1;
}

/* A list build (removing the elements with keep[i] == 0 when keep is given) and what is
 * derived from the list and the state at every build: the scratch grown to the new sizes,
 * the pair classes, the surface and edge elements. */
static cdem_status build_list(cdem_integrator *it, cdem_state *s, const unsigned char *keep,
                              cdem_error *err) {
    it->nb.par_min = it->par_min;
    CDEM_TRY(cdem_neighbour_build(&it->nb, s, keep, 0, err));
    CDEM_TRY(cdem_force_reserve(&it->force, &it->nb, s->n, err));
    CDEM_TRY(reserve_kick(&it->kick, s->n, err));
    CDEM_TRY(cdem_viscous_after_build(&it->viscous, &it->nb, s, err));
    cdem_integrator_classify(it, s);
    return cdem_loads_after_build(&it->loads, s, err);
}

/* The rebuild: escaping elements found and removed with the build. */
static cdem_status rebuild(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    cdem_removal *rm = &it->removal;
    size_t nrem = 0;
    CDEM_TRY(cdem_removal_find_escapes(rm, s, &nrem, err));
    rm->n_removed_last = nrem;
    rm->n_removed += (long)nrem;
    return build_list(it, s, nrem ? rm->keep : NULL, err);
}

void cdem_integrator_classify(cdem_integrator *it, const cdem_state *s) {
    const cdem_contact_law *law = &it->law;
    if (!law->flexural_slip && !law->layered_friction) {
        /* only the weak flag can refine: skip the pass when no element carries it */
        int any = 0;
        for (size_t i = 0; i < s->n && !any; i++)
            any = (s->flags[i] & CDEM_FLAG_WEAK) != 0;
        if (!any)
            return;
    }
    cdem_neighbour *nb = &it->nb;
    for (size_t p = 0; p < nb->np; p++) {
        const int32_t i = nb->pi[p], j = nb->pj[p];
        const int base = nb->cls[p] >= CDEM_CLASS_COUNT ? CDEM_CLASS_ELEMENT : nb->cls[p];
        nb->cls[p] = (uint8_t)cdem_contact_refine(law, base, s->layer[i], s->flags[i], s->layer[j],
                                                  s->flags[j]);
    }
}

static cdem_status check_finite(const cdem_integrator *it, const cdem_state *s, cdem_error *err) {
    const long n = (long)s->n;
    const double *restrict x = s->x, *restrict y = s->y;
    int bad = 0;
#pragma omp parallel for schedule(static) reduction(| : bad) if (n > it->par_min)
    for (long i = 0; i < n; i++)
        bad |= !(isfinite(x[i]) && isfinite(y[i]));
    if (!bad)
        return CDEM_OK;
    for (size_t i = 0; i < s->n; i++)
        if (!(isfinite(s->x[i]) && isfinite(s->y[i])))
            return CDEM_FAIL(err, CDEM_ERR_NUMERIC,
                             "element id %d has a non-finite position (x = %g, y = %g) at step "
                             "%ld: the simulation blew up; likely cause: the time step is too "
                             "large for the spring constants and element masses",
                             (int)s->id[i], s->x[i], s->y[i], it->step);
    return CDEM_OK;
}

/* What a force pass of forces_and_kick does besides the pair forces and the sums. */
enum {
    PASS_KICK = 1 << 0,         /* the damped second half kick of the free elements */
    PASS_CHECK_MOVED = 1 << 1,  /* the rebuild test first: nothing computed when stale */
    PASS_DRIFT = 1 << 2,        /* the step's drift first, in the pass's region */
    PASS_NO_INCREMENT = 1 << 3, /* no tangential increment (dt 0): a configuration's first
                                   forces, with no previous step (prime, removals) */
};

/* The force pass (force.h) of the current step, doing what `what` says (PASS_*), and with
 * PASS_DRIFT the mode's per-element move (may be NULL). Returns 1 (nothing else computed)
 * when PASS_CHECK_MOVED finds the list stale, else 0 with unstable_index updated. */
static int forces_and_kick(cdem_integrator *it, cdem_state *s, unsigned what, cdem_bc_move_fn move,
                           const void *move_ctx) {
    const int kick = (what & PASS_KICK) != 0, drift = (what & PASS_DRIFT) != 0;
    const cdem_force_step in = {
        .law = &it->law,
        .equilibrating = it->equilibrating,
        .dt = (what & PASS_NO_INCREMENT) ? 0.0 : it->dt,
        .damping = cdem_integrator_damping(it),
        .kick = kick,
        .kick_finish = (kick && update_kick(it, s)) ? it->kick.finish : NULL,
        .loads = cdem_loads_of_step(&it->loads),
        .par_min = it->par_min,
        .check_moved = (what & PASS_CHECK_MOVED) != 0,
        .unstable_test = it->unstable_guard,
        .drift = drift,
        .drift_factor = (drift && update_kick(it, s)) ? it->kick.drift : NULL,
        .boundary_move = move,
        .boundary_ctx = move_ctx,
    };
    long unstable = -1;
    if (cdem_force_pass(&it->force, &it->nb, s, &in, &unstable))
        return 1;
    it->unstable_index = unstable;
    return 0;
}

/* The viscous forces (viscous.h) of a configuration's first forces (prime, removals): added
 * to the forces, no kick. */
static void viscous_without_kick(cdem_integrator *it, cdem_state *s) {
    if (!cdem_viscous_active(&it->viscous))
        return;
    cdem_viscous_forces(&it->viscous, &it->nb, s);
    cdem_viscous_finish(&it->viscous, s, 0, 0.0, 0.0);
}

/* The rest of a step with viscous forces (viscous.h), after the drift and the mode: the list
 * brought up to date first (their forces and the pass must see the same element order), their
 * forces at the mid-step velocities, the force pass, and their share of the second kick. */
static cdem_status step_with_viscous(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    if (cdem_neighbour_needs_rebuild(&it->nb, s)) {
        CDEM_TRY(check_finite(it, s, err));
        CDEM_TRY(rebuild(it, s, err));
    }
    cdem_viscous_forces(&it->viscous, &it->nb, s);
    forces_and_kick(it, s, PASS_KICK, NULL, NULL);
    cdem_viscous_finish(&it->viscous, s, 1, it->dt, cdem_integrator_damping(it));
    return CDEM_OK;
}

cdem_status cdem_integrator_prime(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY) && !(s->mass[i] > 0.0))
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "element id %d: mass = %g kg/m: free elements need a mass > 0",
                             (int)s->id[i], s->mass[i]);
    CDEM_TRY(check_finite(it, s, err));
    CDEM_TRY(rebuild(it, s, err));
    forces_and_kick(it, s, PASS_NO_INCREMENT, NULL, NULL);
    viscous_without_kick(it, s);
    return CDEM_OK;
}

/* First half kick and drift of the free elements (cdem_force_drift) in a parallel region of
 * its own: the steps whose mode is not boundary-only (the biaxial servo) or whose list is
 * stale; other steps drift inside the force pass. Threaded over the force pass's chunks
 * when they are current (each thread then moves the elements whose forces it computed and
 * whose rebuild test it makes next: they stay in its cache), else over equal ranges. */
static void drift(cdem_integrator *it, cdem_state *s) {
    const long n = (long)s->n;
    const double *kd = update_kick(it, s) ? it->kick.drift : NULL;
    const int nchunk = cdem_force_chunks_wanted(&it->nb, it->par_min, n);
    const int32_t *ce = cdem_force_current_cut(&it->force, &it->nb, (size_t)n, nchunk);
    const int chunked = ce != NULL;
#pragma omp parallel num_threads(nchunk) if (nchunk > 1)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const int parts = chunked ? nchunk : nt;
        for (int c = t; c < parts; c += nt) {
            const long lo = chunked ? ce[c] : n * c / parts;
            const long hi = chunked ? ce[c + 1] : n * (c + 1) / parts;
            cdem_force_drift(s, it->dt, kd, NULL, lo, hi);
        }
    }
}

cdem_status cdem_integrator_step(cdem_integrator *it, cdem_state *s, cdem_bc *bc, long k, double du,
                                 cdem_error *err) {
    it->removal.n_removed_last = 0;
    if (it->nb.n_builds == 0)
        CDEM_TRY(cdem_integrator_prime(it, s, err));
    /* the drift in the force pass's region when the mode commutes with it (top of file) */
    const int list_current = it->nb.n == s->n;
    const int viscous = cdem_viscous_active(&it->viscous); /* mid-step velocities wanted */
    const int drift_in_pass =
        list_current && !viscous && (!bc || cdem_bc_apply_is_boundary_only(bc, k));
    if (!drift_in_pass)
        drift(it, s);
    it->step++;
    cdem_loads_begin_step(&it->loads, it->step);
    /* a mode whose frame turns sets gravity for this step (bc.h), a process turns it further
     * (gravity_turn) */
    double gx = it->loads.model_gx, gy = it->loads.model_gy;
    int gravity_set = cdem_bc_gravity(bc, k, it->loads.gravity, &gx, &gy);
    if (k >= 1 && it->gravity_turn && it->gravity_turn(it->gravity_turn_ctx, k, &gx, &gy))
        gravity_set = 1;
    if (gravity_set)
        cdem_loads_set_gravity(&it->loads, gx, gy);
    /* a split mode's per-element moves go into the pass's region too (bc.h step_move) */
    const cdem_bc_move_fn move = drift_in_pass ? cdem_bc_step_move_of(bc, k) : NULL;
    if (move)
        CDEM_TRY(cdem_bc_step_begin(bc, k, du, it->dt, err));
    else if (bc)
        CDEM_TRY(cdem_bc_apply(bc, s, k, du, it->dt, err));
    if (viscous)
        return step_with_viscous(it, s, err);
    /* the rebuild test (cdem_neighbour_needs_rebuild) is made inside the force pass */
    if (list_current &&
        forces_and_kick(it, s, PASS_KICK | PASS_CHECK_MOVED | (drift_in_pass ? PASS_DRIFT : 0u),
                        move, move ? cdem_bc_step_move_ctx(bc) : NULL) == 0)
        return CDEM_OK;
    CDEM_TRY(check_finite(it, s, err));
    CDEM_TRY(rebuild(it, s, err));
    forces_and_kick(it, s, PASS_KICK, NULL, NULL);
    return CDEM_OK;
}

/* Removes the elements marked 0 in removal.keep (nrem of them) through the path escaping
 * elements take: ids to removed_ids, state compacted with histories kept, pair classes and
 * surface re-derived, and the forces of the new configuration evaluated without a
 * tangential increment or a kick (as in prime). */
static cdem_status remove_marked(cdem_integrator *it, cdem_state *s, size_t nrem, cdem_error *err) {
    CDEM_TRY(cdem_removal_collect(&it->removal, s, nrem, err));
    it->removal.n_removed_last = nrem;
    CDEM_TRY(build_list(it, s, it->removal.keep, err));
    forces_and_kick(it, s, PASS_NO_INCREMENT, NULL, NULL);
    viscous_without_kick(it, s);
    return CDEM_OK;
}

cdem_status cdem_integrator_erode(cdem_integrator *it, cdem_state *s, double ymax, long *count,
                                  cdem_error *err) {
    if (count)
        *count = 0;
    it->removal.n_removed_last = 0;
    size_t nrem = 0;
    CDEM_TRY(cdem_removal_mark_above(&it->removal, s, ymax, &nrem, err));
    if (nrem == 0)
        return CDEM_OK;
    CDEM_TRY(remove_marked(it, s, nrem, err));
    it->removal.n_removed += (long)nrem;
    if (count)
        *count = (long)nrem;
    return CDEM_OK;
}

cdem_status cdem_integrator_begin_deformation(cdem_integrator *it, cdem_state *s, cdem_bc *bc,
                                              size_t *n_removed, cdem_error *err) {
    *n_removed = 0;
    it->removal.n_removed_last = 0;
    if (!bc)
        return CDEM_OK;
    if (it->nb.n_builds == 0)
        CDEM_TRY(cdem_integrator_prime(it, s, err));
    size_t nrem = 0;
    CDEM_TRY(cdem_removal_mark_by_mode(&it->removal, s, bc, &nrem, err));
    if (nrem == 0)
        return CDEM_OK;
    CDEM_TRY(remove_marked(it, s, nrem, err));
    *n_removed = nrem;
    return CDEM_OK;
}

long cdem_integrator_make_cohesive(cdem_integrator *it, const cdem_state *s) {
    (void)s;
    const uint8_t flag =
        it->law.model == CDEM_MATERIAL_BONDED ? CDEM_PAIR_BONDED : CDEM_PAIR_COHESIVE;
    /* cohesive_contacts = initial: only the contacts of the built assembly that never
     * separated; the marks have served and are cleared */
    const uint8_t need =
        it->law.model == CDEM_MATERIAL_GRANULAR && it->law.cohesive_rule == CDEM_COHESIVE_INITIAL
            ? (uint8_t)(CDEM_PAIR_TOUCH | CDEM_PAIR_INITIAL)
            : (uint8_t)CDEM_PAIR_TOUCH;
    long count = 0;
    for (size_t p = 0; p < it->nb.np; p++) {
        uint8_t h = it->nb.hist[p];
        if ((h & need) == need && it->nb.cls[p] != CDEM_CLASS_SLIP) {
            h |= flag;
            count++;
        }
        it->nb.hist[p] = (uint8_t)(h & ~CDEM_PAIR_INITIAL);
    }
    return count;
}

long cdem_integrator_mark_initial(cdem_integrator *it, const cdem_state *s) {
    if (it->law.model != CDEM_MATERIAL_GRANULAR || it->law.cohesive_rule != CDEM_COHESIVE_INITIAL ||
        it->nb.n != s->n)
        return 0;
    const cdem_neighbour *nb = &it->nb;
    long count = 0;
    for (size_t p = 0; p < nb->np; p++) {
        const int32_t i = nb->pi[p], j = nb->pj[p];
        const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i], R = nb->R[p];
        const double r2 = dx * dx + dy * dy;
        if (r2 > 0.0 && r2 < R * R * CDEM_INITIAL_REACH2) {
            it->nb.hist[p] |= CDEM_PAIR_INITIAL;
            count++;
        }
    }
    return count;
}

void cdem_integrator_count(const cdem_integrator *it, long *contacts, long *bonds) {
    long c = 0, b = 0;
    for (size_t p = 0; p < it->nb.np; p++) {
        const uint8_t h = it->nb.hist[p];
        c += (h & CDEM_PAIR_TOUCH) != 0;
        b += (h & (CDEM_PAIR_COHESIVE | CDEM_PAIR_BONDED)) != 0;
    }
    if (contacts)
        *contacts = c;
    if (bonds)
        *bonds = b;
}

/* ---------------------------------------------------------------- checkpoints */

cdem_status cdem_integrator_snapshot_put(const cdem_integrator *it, int boundary_forces,
                                         cdem_snapshot *snap, cdem_error *err) {
    const char *P = "it";
    const cdem_loads *ld = &it->loads;
    const cdem_removal *rm = &it->removal;
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "dt", it->dt, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "damping", it->damping, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "gravity", ld->gravity, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "gravity_x", ld->gravity_x, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "gravity_y", ld->gravity_y, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "overburden_force", ld->overburden_force, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "confining_pressure", ld->confining_pressure, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "step", it->step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "boundary_forces", boundary_forces, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "bounds_set", rm->bounds_set, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "escape_xmin", rm->escape_xmin, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "escape_xmax", rm->escape_xmax, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "escape_ymin", rm->escape_ymin, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_removed", rm->n_removed, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_surface", ld->n_surface, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_edge", ld->n_edge, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "confining_factor", ld->confining_factor, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "edge_x_mid", ld->edge_x_mid, err));
    CDEM_TRY(cdem_contact_snapshot_put(&it->law, snap, err));
    return cdem_neighbour_snapshot_put(&it->nb, snap, err);
}

cdem_status cdem_integrator_snapshot_get(cdem_integrator *it, const cdem_snapshot *snap,
                                         const cdem_state *s, int *boundary_forces,
                                         cdem_error *err) {
    const char *P = "it";
    cdem_loads *ld = &it->loads;
    cdem_removal *rm = &it->removal;
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "dt", it->dt, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "damping", it->damping, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "gravity", ld->gravity, err));
    /* the direction of the step the checkpoint follows (a mode may turn it: bc.h); absent
     * from checkpoints written before gravity was a vector, whose gravity was straight down,
     * as cdem_loads_init set it */
    if (cdem_snapshot_get(snap, "it.gravity_x") || cdem_snapshot_get(snap, "it.gravity_y")) {
        CDEM_TRY(cdem_ckpt_get_f64(snap, P, "gravity_x", &ld->gravity_x, err));
        CDEM_TRY(cdem_ckpt_get_f64(snap, P, "gravity_y", &ld->gravity_y, err));
    }
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "overburden_force", ld->overburden_force, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "confining_pressure", ld->confining_pressure, err));
    CDEM_TRY(cdem_contact_snapshot_check(&it->law, snap, err));
    int64_t step = 0, bf = 0, bounds = 0, n_removed = 0, n_surface = 0, n_edge = 0;
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "step", 0, INT64_MAX, &step, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "boundary_forces", 0, 1, &bf, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "bounds_set", 0, 1, &bounds, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "n_removed", 0, INT64_MAX, &n_removed, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "n_surface", 0, INT64_MAX, &n_surface, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "n_edge", 0, INT64_MAX, &n_edge, err));
    double exmin = 0.0, exmax = 0.0, eymin = 0.0, cf = 0.0, exmid = 0.0;
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "escape_xmin", &exmin, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "escape_xmax", &exmax, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "escape_ymin", &eymin, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "confining_factor", &cf, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "edge_x_mid", &exmid, err));
    CDEM_TRY(cdem_neighbour_snapshot_get(&it->nb, snap, s, err));
    CDEM_TRY(cdem_viscous_after_build(&it->viscous, &it->nb, s, err));
    CDEM_TRY(cdem_removal_reserve(rm, s->n, err));
    CDEM_TRY(cdem_force_reserve(&it->force, &it->nb, s->n, err));
    CDEM_TRY(reserve_kick(&it->kick, s->n, err));
    it->step = (long)step;
    *boundary_forces = (int)bf;
    rm->bounds_set = (int)bounds;
    rm->escape_xmin = exmin;
    rm->escape_xmax = exmax;
    rm->escape_ymin = eymin;
    rm->n_removed = (long)n_removed;
    ld->n_surface = (long)n_surface;
    ld->n_edge = (long)n_edge;
    ld->confining_factor = cf;
    ld->edge_x_mid = exmid;
    rm->n_removed_last = 0;
    return CDEM_OK;
}
