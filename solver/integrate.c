/* integrate: see integrate.h. The step is: (1) half kick + drift of the free elements
 * (over the force pass's chunks; the boundary mode moves its elements after it), (2) one
 * force pass (forces_and_kick): the rebuild test, then the pair loop (chunk_pass) computes
 * each pair force once into its slot and scatters it to its two elements, then the
 * elements are finished (second half kick, instability guard).
 * Threads: the elements are cut into one chunk per thread, by estimated work and then by
 * measured thread times (make_chunks, update_shares); a pair is evaluated by the chunk of
 * its second element, so a pair whose two elements lie in different chunks (a cross pair)
 * is evaluated first by the later chunk, which publishes its progress; the earlier chunk
 * waits only if it reaches a cross pair not yet evaluated. Each element's sum has the same
 * additions in the same order (ascending pair index) for any cut, so any thread count and
 * any cut give identical bits, the same as the serial scatter. Two parallel regions and one
 * barrier per step. */
#include "integrate.h"

#include "checkpoint.h"
#include "parallel.h"
#include "surface.h"

#include <math.h>
#include <omp.h>
#include <sched.h>
#include <stdatomic.h>
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
    it->boundary_forces = 1;
    it->dt = m->dt;
    it->damping = m->damping;
    it->gravity = m->gravity;
    it->max_radius = m->max_radius > 0.0 ? m->max_radius : m->radius[CDEM_NUM_RADII - 1];
    it->column_width = 2.0 * it->max_radius;
    CDEM_TRY(cdem_contact_law_init(&it->law, p, m->kn, m->ks, err));
    CDEM_TRY(cdem_neighbour_init(&it->nb, 0.25 * m->radius[0], 1.0 + it->law.max_breaking_strain,
                                 RESORT_EVERY, err));
    return CDEM_OK;
}

void cdem_integrator_free(cdem_integrator *it) {
    if (!it)
        return;
    cdem_neighbour_free(&it->nb);
    free(it->keep);
    free(it->removed_ids);
    free(it->col_top);
    free(it->band_lo);
    free(it->band_hi);
    free(it->cross);
    free(it->kick_drift);
    free(it->kick_finish);
    free(it->elem_work);
    memset(it, 0, sizeof *it);
}

void cdem_integrator_enable_escape(cdem_integrator *it) {
    it->bounds_set = 1;
}

static int is_free(uint32_t flags) {
    return !(flags & CDEM_FLAGS_BOUNDARY);
}

static cdem_status reserve_keep(cdem_integrator *it, size_t n, cdem_error *err) {
    if (n <= it->keepcap)
        return CDEM_OK;
    size_t c = n + n / 2 + 16;
    unsigned char *k = realloc(it->keep, c);
    if (!k)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu elements)", c);
    it->keep = k;
    it->keepcap = c;
    return CDEM_OK;
}

/* Copies the ids of the elements with keep[i] == 0 (nrem of them) to removed_ids. */
static cdem_status collect_removed(cdem_integrator *it, const cdem_state *s, size_t nrem,
                                   cdem_error *err) {
    if (nrem > it->removed_cap) {
        size_t c = nrem + it->removed_cap + 16;
        int32_t *q = realloc(it->removed_ids, c * sizeof *q);
        if (!q)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu ids)", c);
        it->removed_ids = q;
        it->removed_cap = c;
    }
    size_t k = 0;
    for (size_t i = 0; i < s->n && k < nrem; i++)
        if (!it->keep[i])
            it->removed_ids[k++] = s->id[i];
    return CDEM_OK;
}

/* Marks escaping free elements in it->keep; returns how many. */
static cdem_status find_escapes(cdem_integrator *it, const cdem_state *s, size_t *count,
                                cdem_error *err) {
    *count = 0;
    if (!it->bounds_set)
        return CDEM_OK;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_WALL))
            continue;
        /* plain comparisons, not the fmin/fmax library calls (this runs at every build) */
        const double xi = s->x[i], yi = s->y[i];
        xmin = xi < xmin ? xi : xmin;
        xmax = xi > xmax ? xi : xmax;
        ymin = yi < ymin ? yi : ymin;
    }
    if (!isfinite(xmin))
        return CDEM_OK; /* no walls: nothing to escape from */
    it->escape_xmin = xmin;
    it->escape_xmax = xmax;
    it->escape_ymin = ymin;
    CDEM_TRY(reserve_keep(it, s->n, err));
    size_t nrem = 0;
    for (size_t i = 0; i < s->n; i++) {
        int out = 0;
        if (is_free(s->flags[i])) {
            const double r = s->radius[i];
            out = s->x[i] < xmin - r || s->x[i] > xmax + r || s->y[i] < ymin - it->max_radius;
        }
        it->keep[i] = (unsigned char)!out;
        nrem += (size_t)out;
    }
    *count = nrem;
    return collect_removed(it, s, nrem, err);
}

/* Grows the cross-pair buffer to the pair capacity (after a list build, outside the step's
 * hot loops). */
static cdem_status reserve_cross(cdem_integrator *it, cdem_error *err) {
    if (it->crosscap >= it->nb.pcap)
        return CDEM_OK;
    const size_t c = it->nb.pcap;
    int32_t *q = realloc(it->cross, (c ? c : 1) * sizeof *q);
    if (!q)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu cross pairs)", c);
    it->cross = q;
    it->crosscap = c;
    return CDEM_OK;
}

/* Grows the per-element scratch (kick factors, chunk work) to n elements (after a list
 * build, outside the step's hot loops). */
static cdem_status reserve_per_element(cdem_integrator *it, size_t n, cdem_error *err) {
    if (it->kickcap >= n)
        return CDEM_OK;
    const size_t c = n + n / 2 + 16;
    double *a = realloc(it->kick_drift, c * sizeof *a);
    if (a)
        it->kick_drift = a;
    double *b = a ? realloc(it->kick_finish, c * sizeof *b) : NULL;
    if (b)
        it->kick_finish = b;
    uint32_t *w = b ? realloc(it->elem_work, c * sizeof *w) : NULL;
    if (!w)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu elements)", c);
    it->elem_work = w;
    it->kickcap = c;
    return CDEM_OK;
}

/* The kick factors for the current masses, dt and damping (integrate.h), when stale. The
 * expressions are those the kicks used to evaluate every step, so the bits are the same.
 * Returns 0 when they cannot be had without allocating (elements appended since the last
 * build): the kicks then divide as before. */
static int update_kick(cdem_integrator *it, const cdem_state *s) {
    if (it->kickcap < s->n)
        return 0;
    const double c = cdem_integrator_damping(it);
    if (it->kick_build == it->nb.n_builds && it->kick_n == s->n && it->kick_dt == it->dt &&
        it->kick_c == c)
        return 1;
    const double hdt = 0.5 * it->dt;
    const long n = (long)s->n;
    const double *restrict mass = s->mass;
    double *restrict kd = it->kick_drift, *restrict kf = it->kick_finish;
#pragma omp parallel for schedule(static) if (n > it->par_min)
    for (long i = 0; i < n; i++) {
        kd[i] = hdt / mass[i];
        kf[i] = 1.0 / (mass[i] + c * hdt);
    }
    it->kick_build = it->nb.n_builds;
    it->kick_n = s->n;
    it->kick_dt = it->dt;
    it->kick_c = c;
    return 1;
}

/* A list build (removing the elements with keep[i] == 0 when keep is given) and what is
 * derived from the list and the state at every build: the scratch grown to the new sizes,
 * the pair classes, the surface and edge elements. */
static cdem_status build_list(cdem_integrator *it, cdem_state *s, const unsigned char *keep,
                              cdem_error *err) {
    it->nb.par_min = it->par_min;
    CDEM_TRY(cdem_neighbour_build(&it->nb, s, keep, 0, err));
    CDEM_TRY(reserve_cross(it, err));
    CDEM_TRY(reserve_per_element(it, s->n, err));
    cdem_integrator_classify(it, s);
    if (it->overburden_force > 0.0)
        CDEM_TRY(cdem_integrator_find_surface(it, s, err));
    if (it->confining_pressure > 0.0)
        CDEM_TRY(cdem_integrator_find_edges(it, s, err));
    return CDEM_OK;
}

static cdem_status rebuild(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    size_t nrem = 0;
    CDEM_TRY(find_escapes(it, s, &nrem, err));
    it->n_removed_last = nrem;
    it->n_removed += (long)nrem;
    return build_list(it, s, nrem ? it->keep : NULL, err);
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

cdem_status cdem_integrator_set_overburden(cdem_integrator *it, double pressure, cdem_error *err) {
    if (!isfinite(pressure) || pressure < 0.0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: surface.overburden_pressure = %g N/m: must be a finite "
                         "number >= 0",
                         pressure);
    it->overburden_pressure = pressure;
    it->overburden_force = pressure * it->column_width;
    return CDEM_OK;
}

cdem_status cdem_integrator_set_confining(cdem_integrator *it, double pressure, long equil_steps,
                                          cdem_error *err) {
    if (!isfinite(pressure) || pressure < 0.0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: boundary.confining_pressure = %g N/m: must be a finite "
                         "number >= 0",
                         pressure);
    it->confining_pressure = pressure;
    it->confining_equil = equil_steps;
    it->confining_factor = cdem_bc_confining_ramp(it->step, equil_steps);
    return CDEM_OK;
}

cdem_status cdem_integrator_find_edges(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    double ymin = INFINITY, ymax = -INFINITY, xmin = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~(uint32_t)CDEM_FLAG_BIAXIAL_EDGE;
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        ymin = fmin(ymin, s->y[i]);
        ymax = fmax(ymax, s->y[i]);
        xmin = fmin(xmin, s->x[i]);
        xmax = fmax(xmax, s->x[i]);
    }
    it->n_edge = 0;
    if (!isfinite(ymin) || !(it->column_width > 0.0))
        return CDEM_OK;
    it->edge_x_mid = 0.5 * (xmin + xmax);
    const double w = it->column_width;
    const double span = (ymax - ymin) / w;
    if (!(span < 1e8))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: free elements span %g m = %g bands of %g m: too many for "
                         "the edge search",
                         ymax - ymin, span, w);
    const size_t nb = (size_t)span + 1;
    if (nb > it->bandcap) {
        const size_t c = nb + nb / 2 + 16;
        int32_t *lo = realloc(it->band_lo, c * sizeof *lo);
        if (lo)
            it->band_lo = lo;
        int32_t *hi = lo ? realloc(it->band_hi, c * sizeof *hi) : NULL;
        if (!lo || !hi)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu bands)", c);
        it->band_hi = hi;
        it->bandcap = c;
    }
    for (size_t b = 0; b < nb; b++)
        it->band_lo[b] = it->band_hi[b] = -1;
    const cdem_grid bands = {.x0 = 0.0, .y0 = ymin, .cell = w, .nx = 1, .ny = nb};
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        const size_t b = cdem_grid_row(&bands, s->y[i]);
        const int32_t lo = it->band_lo[b], hi = it->band_hi[b];
        if (lo < 0 || s->x[i] < s->x[lo])
            it->band_lo[b] = (int32_t)i;
        if (hi < 0 || s->x[i] > s->x[hi])
            it->band_hi[b] = (int32_t)i;
    }
    long count = 0;
    for (size_t b = 0; b < nb; b++) {
        const int32_t e[2] = {it->band_lo[b], it->band_hi[b]};
        for (int k = 0; k < 2; k++) {
            if (e[k] < 0 || (s->flags[e[k]] & CDEM_FLAG_BIAXIAL_EDGE))
                continue;
            s->flags[e[k]] |= CDEM_FLAG_BIAXIAL_EDGE;
            count++;
        }
    }
    it->n_edge = count;
    return CDEM_OK;
}

cdem_status cdem_integrator_find_surface(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    double xmin = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~(uint32_t)CDEM_FLAG_SURFACE;
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        xmin = fmin(xmin, s->x[i]);
        xmax = fmax(xmax, s->x[i]);
    }
    it->n_surface = 0;
    if (!isfinite(xmin) || !(it->column_width > 0.0))
        return CDEM_OK;
    const double w = it->column_width;
    const double span = (xmax - xmin) / w;
    if (!(span < 1e8))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: free elements span %g m = %g columns of %g m: too many "
                         "for the surface search",
                         xmax - xmin, span, w);
    const size_t ncol = (size_t)span + 1;
    if (ncol > it->colcap) {
        size_t c = ncol + ncol / 2 + 16;
        size_t *q = realloc(it->col_top, c * sizeof *q);
        if (!q)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu columns)", c);
        it->col_top = q;
        it->colcap = c;
    }
    const cdem_grid cols = {.x0 = xmin, .y0 = 0.0, .cell = w, .nx = ncol, .ny = 1};
    cdem_surface_columns(s, &cols, CDEM_SURFACE_BY_CENTRE, -INFINITY, INFINITY, it->col_top);
    long count = 0;
    for (size_t c = 0; c < ncol; c++) {
        if (it->col_top[c] == SIZE_MAX)
            continue;
        s->flags[it->col_top[c]] |= CDEM_FLAG_SURFACE;
        count++;
    }
    it->n_surface = count;
    return CDEM_OK;
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

/* Force of pair p on its pi into the slot pfx[p], pfy[p] (zero when it does not touch):
 * the common case of a list pair that does not touch is settled here, everything else by
 * the one contact kernel (contact.h). (A branch-free variant of the granular law,
 * evaluating every list pair and selecting the result, was measured 40-50 % slower: gcc -O2
 * still branches and does more work.) */
static CDEM_INLINE void pair_force(const cdem_contact_law *restrict law, long p, double dx,
                                   double dy, double dvx, double dvy, const double *restrict Rp,
                                   const uint8_t *restrict cls, uint8_t *restrict hist,
                                   double *restrict xs, double *restrict pfx, double *restrict pfy,
                                   double dt) {
    const double R = Rp[p];
    const uint8_t h = hist[p];
    const double r2 = dx * dx + dy * dy;
    if (!(h & CDEM_PAIR_BONDED)) {
        if (r2 >= R * R || r2 <= 0.0) {
            /* separated: xs != 0 only with h != 0 */
            pfx[p] = 0.0;
            pfy[p] = 0.0;
            if (h) {
                hist[p] = cdem_contact_separated(h, r2, R);
                xs[p] = 0.0;
            }
            return;
        }
        cdem_contact_touching(law, cls[p], r2, dx, dy, R, dvx, dvy, dt, &xs[p], &hist[p], &pfx[p],
                              &pfy[p]);
        return;
    }
    cdem_contact_eval(law, cls[p], dx, dy, R, dvx, dvy, dt, &xs[p], &hist[p], &pfx[p], &pfy[p]);
}

/* Finishes element i from its contact-force sum (sx, sy): gravity, the damped second half
 * kick (when kick), and the total force stored in fx, fy. Boundary elements keep the sum. */
static inline void finish_element(long i, double sx, double sy, const double *restrict mass,
                                  const double *restrict kick_finish,
                                  const uint32_t *restrict flags, double *restrict vxw,
                                  double *restrict vyw, double *restrict fx, double *restrict fy,
                                  double hdt, double c, double g, double ob, int kick,
                                  const double *restrict x, double ef, double exmid) {
    const uint32_t fl = flags[i];
    if (fl & CDEM_FLAGS_BOUNDARY) {
        fx[i] = sx;
        fy[i] = sy;
        return;
    }
    const double m = mass[i];
    sy -= m * g + ((fl & CDEM_FLAG_SURFACE) ? ob : 0.0);
    if (fl & CDEM_FLAG_BIAXIAL_EDGE)
        sx += x[i] < exmid ? ef : -ef;
    if (kick) {
        /* v = (v_half + hdt/m F) / (1 + c hdt/m), with 1 / (m + c hdt) from kick_finish */
        const double inv = kick_finish ? kick_finish[i] : 1.0 / (m + c * hdt);
        vxw[i] = (m * vxw[i] + hdt * sx) * inv;
        vyw[i] = (m * vyw[i] + hdt * sy) * inv;
    }
    fx[i] = sx - c * vxw[i];
    fy[i] = sy - c * vyw[i];
}

/* Everything the force pass reads or writes, gathered once per step. */
typedef struct {
    const cdem_contact_law *law;
    int kick;
    double dt, hdt, c, g, ob, ef, exmid;
    const double *x, *y, *mass, *Rp;
    const double *kick_finish; /* it->kick_finish (integrate.h) */
    const int32_t *pi, *pj, *istart;
    const uint8_t *cls;
    const uint32_t *flags;
    uint8_t *hist;
    double *xs, *pfx, *pfy, *fx, *fy, *vx, *vy;
    const double *radius; /* element radii (the unstable-motion guard), NULL: guard off */
    int nchunk;           /* chunks of this pass */
    const int32_t *chunk_elem, *cross_start, *cross; /* the decomposition (integrate.h) */
    cdem_integrator *it;                             /* cross_done progress slots */
    long unstable[CDEM_MAX_CHUNKS];  /* per chunk: lowest unstable element index, or -1 */
    double seconds[CDEM_MAX_CHUNKS]; /* per thread: time in this pass (load balance) */
} force_pass;

/* How many cross pairs a chunk evaluates between two publications of its progress: small
 * enough that an earlier chunk seldom waits, large enough that the shared line is rarely
 * written. */
#define CROSS_PUBLISH_EVERY 32

static int32_t cross_progress(const force_pass *fp, int d) {
    return atomic_load_explicit(&fp->it->cross_done[d].slot, memory_order_acquire);
}

/* Waits until every chunk after c has evaluated its cross pairs at slots below `slot` (their
 * slots are read by chunk c) and returns the lowest slot below which all of them are done,
 * so that the caller need not look again before it. Usually no wait at all: the later
 * chunks' threads go through their few cross pairs in ascending slot order, ahead of chunk
 * c's scan through all of its pairs. */
static int32_t wait_cross(const force_pass *fp, int c, int32_t slot) {
    int32_t safe = INT32_MAX;
    for (int d = c + 1; d < fp->nchunk; d++) {
        int32_t v = cross_progress(fp, d);
        for (long spins = 0; v < slot; spins++) {
            if (spins > 1000)
                sched_yield(); /* the other thread may be descheduled (shared machine) */
            v = cross_progress(fp, d);
        }
        if (v < safe)
            safe = v;
    }
    return safe;
}

static void publish_cross(const force_pass *fp, int c, int32_t slot) {
    atomic_store_explicit(&fp->it->cross_done[c].slot, slot, memory_order_release);
}

/* Evaluates the cross pairs into chunk c (their slots only; no sums), in ascending slot
 * order, publishing the progress every CROSS_PUBLISH_EVERY pairs. */
static void cross_eval(const force_pass *fp, int c) {
    const double *restrict x = fp->x, *restrict y = fp->y;
    const double *restrict vx = fp->vx, *restrict vy = fp->vy;
    const int32_t *restrict list = fp->cross;
    const int32_t a = fp->cross_start[c], b = fp->cross_start[c + 1];
    for (int32_t k = a; k < b; k++) {
        const long p = list[k];
        const int32_t i = fp->pi[p], j = fp->pj[p];
        pair_force(fp->law, p, x[j] - x[i], y[j] - y[i], vx[j] - vx[i], vy[j] - vy[i], fp->Rp,
                   fp->cls, fp->hist, fp->xs, fp->pfx, fp->pfy, fp->dt);
        if ((k - a) % CROSS_PUBLISH_EVERY == CROSS_PUBLISH_EVERY - 1 && k + 1 < b)
            publish_cross(fp, c, list[k + 1]);
    }
    publish_cross(fp, c, INT32_MAX);
}

/* The force pass over the elements lo..hi-1 and their pi ranges (pairs istart[lo] ..
 * istart[hi]-1). Every element's sum is built in ascending pair order, as one scatter loop
 * over all pairs would: fx, fy of the chunk start at zero, the cross pairs from earlier
 * chunks (list[ca..cb-1], ascending, already evaluated) are subtracted first, then the
 * chunk's pairs are scattered in order (a pair whose pj lies in a later chunk was evaluated
 * by that chunk's thread and only adds to its pi here). Then the chunk's elements are
 * finished. (A loop nested per element, accumulating each pi range in registers and
 * finishing the element right after it, was measured slower: the short inner loops
 * mispredict their exits.) */
static void chunk_pass(force_pass *fp, int chunk) {
    const long lo = fp->chunk_elem[chunk], hi = fp->chunk_elem[chunk + 1];
    const int32_t *restrict list = fp->cross;
    const int32_t ca = fp->cross_start[chunk], cb = fp->cross_start[chunk + 1];
    const cdem_contact_law *restrict law = fp->law;
    const double *restrict x = fp->x, *restrict y = fp->y;
    double *restrict vx = fp->vx, *restrict vy = fp->vy;
    const int32_t *restrict pj = fp->pj, *restrict istart = fp->istart;
    double *restrict fx = fp->fx, *restrict fy = fp->fy;
    double *restrict pfx = fp->pfx, *restrict pfy = fp->pfy;
    const double dt = fp->dt;
    memset(fx + lo, 0, (size_t)(hi - lo) * sizeof *fx);
    memset(fy + lo, 0, (size_t)(hi - lo) * sizeof *fy);
    for (int32_t k = ca; k < cb; k++) {
        const long p = list[k];
        fx[pj[p]] -= pfx[p];
        fy[pj[p]] -= pfy[p];
    }
    const int32_t *restrict pi = fp->pi;
    const long p0 = istart[lo], pe = istart[hi];
    /* cross pairs at slots below `safe` are evaluated (the last chunk has none out) */
    int32_t safe = chunk + 1 >= fp->nchunk ? INT32_MAX : 0;
    for (long p = p0; p < pe; p++) {
        const int32_t i = pi[p], j = pj[p];
        if (j < hi) {
            pair_force(law, p, x[j] - x[i], y[j] - y[i], vx[j] - vx[i], vy[j] - vy[i], fp->Rp,
                       fp->cls, fp->hist, fp->xs, pfx, pfy, dt);
            fx[j] -= pfx[p];
            fy[j] -= pfy[p];
            fx[i] += pfx[p];
            fy[i] += pfy[p];
        } else {
            /* a cross pair: evaluated by the chunk of j (not through the restrict pointers) */
            if (p >= safe)
                safe = wait_cross(fp, chunk, (int32_t)p + 1);
            fx[i] += fp->pfx[p];
            fy[i] += fp->pfy[p];
        }
    }
    /* the cross pairs out of this chunk read its velocities: kick only after all of them */
    if (pe > safe)
        wait_cross(fp, chunk, (int32_t)pe);
    for (long i = lo; i < hi; i++)
        finish_element(i, fx[i], fy[i], fp->mass, fp->kick_finish, fp->flags, vx, vy, fx, fy,
                       fp->hdt, fp->c, fp->g, fp->ob, fp->kick, x, fp->ef, fp->exmid);
    fp->unstable[chunk] = -1;
    if (fp->radius) {
        /* the run loop's guard (integrate.h): here, while the velocities are in cache */
        const double *restrict rad = fp->radius;
        const double dt2 = fp->dt * fp->dt;
        for (long i = lo; i < hi; i++) {
            const double d2 = (vx[i] * vx[i] + vy[i] * vy[i]) * dt2;
            if (d2 > rad[i] * rad[i]) {
                fp->unstable[chunk] = i;
                break;
            }
        }
    }
}

/* Relative costs of the work of a step (measured at 9,000 elements: a touching pair's law
 * ~10 ns, a list pair that does not touch ~3 ns, a free element's drift, rebuild test and
 * finish ~4 ns, a boundary element's ~1 ns); only their ratios matter. */
enum { WORK_TOUCH = 10, WORK_APART = 3, WORK_FREE = 4, WORK_BOUNDARY = 1 };

/* Work of element e in a threaded step: its drift and finish, and the pairs whose pj it is
 * (each pair is evaluated by the chunk of its pj). The touch flags are those of the last
 * evaluation (carried over by the build). */
static uint32_t element_work(const cdem_neighbour *nb, const uint32_t *flags, size_t e) {
    uint32_t w = (flags[e] & CDEM_FLAGS_BOUNDARY) ? WORK_BOUNDARY : WORK_FREE;
    for (int32_t k = nb->jstart[e]; k < nb->jstart[e + 1]; k++)
        w += (nb->hist[nb->jslot[k]] & CDEM_PAIR_TOUCH) ? WORK_TOUCH : WORK_APART;
    return w;
}

/* The work shares of the next cut: equal for a new chunk count; else each share scaled by
 * the speed its thread showed since the last cut (share / mean time), so that the times
 * even out, smoothed (half way) and kept above a tenth of an equal share. */
static void update_shares(cdem_integrator *it, int nchunk) {
    if (it->share_n != nchunk) {
        it->share_n = nchunk;
        for (int c = 0; c < nchunk; c++) {
            it->chunk_share[c] = 1.0 / nchunk;
            it->chunk_time[c] = 0.0;
        }
        return;
    }
    double speed[CDEM_MAX_CHUNKS], sum = 0.0;
    for (int c = 0; c < nchunk; c++) {
        if (!(it->chunk_time[c] > 0.0))
            return; /* a chunk without a measurement: keep the shares */
        speed[c] = it->chunk_share[c] / it->chunk_time[c];
        sum += speed[c];
    }
    double total = 0.0;
    for (int c = 0; c < nchunk; c++) {
        double share = 0.5 * (it->chunk_share[c] + speed[c] / sum);
        if (share < 0.1 / nchunk)
            share = 0.1 / nchunk;
        it->chunk_share[c] = share;
        total += share;
    }
    for (int c = 0; c < nchunk; c++) {
        it->chunk_share[c] /= total;
        it->chunk_time[c] = 0.0;
    }
}

/* Splits the elements into nchunk ranges of about equal work (element_work) and lists the
 * cross pairs of each chunk. A pair is evaluated by the chunk of its pj: its own pairs and
 * the cross pairs coming in from earlier chunks, e.g. every element-wall pair goes to the
 * chunk of the walls, which are sorted to the end; cutting at equal pair counts by pi
 * instead overloaded that chunk (20 % more pairs at 9,000 elements), and equal pair counts
 * by pj still left the lower chunk, with more touching pairs and free elements, 10 % more
 * to do. The cut does not change any result (every element sum has the same additions in
 * the same order for any cut). Falls back to one chunk when the buffer is too small (never
 * after a build through rebuild/remove_marked, which reserve it). */
static void make_chunks(cdem_integrator *it, const uint32_t *flags, size_t n, int nchunk) {
    const cdem_neighbour *nb = &it->nb;
    const size_t np = nb->np;
    if (nchunk > CDEM_MAX_CHUNKS)
        nchunk = CDEM_MAX_CHUNKS;
    if (nchunk < 1 || (size_t)nchunk > n || it->crosscap < np)
        nchunk = 1;
    it->nchunk = nchunk;
    it->chunk_build = nb->n_builds;
    it->chunk_n = n;
    it->chunk_elem[0] = 0;
    if (nchunk > 1) {
        update_shares(it, nchunk);
        /* each element's work once (in parallel when there is room to keep it), then the
         * running sum */
        uint32_t *restrict work = it->kickcap >= n ? it->elem_work : NULL;
        if (work) {
#pragma omp parallel for schedule(static) if ((long)n > it->par_min)
            for (long e = 0; e < (long)n; e++)
                work[e] = element_work(nb, flags, (size_t)e);
        }
        uint64_t total = 0;
        for (size_t e = 0; e < n; e++)
            total += work ? work[e] : element_work(nb, flags, e);
        /* chunk c starts at the first element with at least the shares of chunks 0..c-1 of
         * the work before it */
        double cum = 0.0;
        uint64_t want[CDEM_MAX_CHUNKS];
        for (int c = 1; c < nchunk; c++) {
            cum += it->chunk_share[c - 1];
            want[c] = (uint64_t)(cum * (double)total);
        }
        uint64_t before = 0;
        int c = 1;
        for (size_t e = 0; e < n && c < nchunk; e++) {
            while (c < nchunk && before >= want[c])
                it->chunk_elem[c++] = (int32_t)e;
            before += work ? work[e] : element_work(nb, flags, e);
        }
        while (c < nchunk)
            it->chunk_elem[c++] = (int32_t)n;
    }
    it->chunk_elem[nchunk] = (int32_t)n;
    for (int c = 0; c <= nchunk; c++)
        it->cross_start[c] = 0;
    if (nchunk == 1)
        return;
    /* count, then fill, the cross pairs by the chunk of pj (ascending slots in each) */
    for (int pass = 0; pass < 2; pass++) {
        int32_t cursor[CDEM_MAX_CHUNKS + 1];
        for (int c = 0; c <= nchunk; c++)
            cursor[c] = it->cross_start[c];
        for (int ci = 0; ci < nchunk; ci++) {
            const int32_t end = it->chunk_elem[ci + 1];
            for (int32_t p = nb->istart[it->chunk_elem[ci]]; p < nb->istart[end]; p++) {
                const int32_t j = nb->pj[p];
                if (j < end)
                    continue;
                int cj = ci + 1;
                while (j >= it->chunk_elem[cj + 1])
                    cj++;
                if (pass == 0)
                    cursor[cj + 1]++;
                else
                    it->cross[cursor[cj]++] = p;
            }
        }
        if (pass == 0)
            for (int c = 0; c < nchunk; c++)
                it->cross_start[c + 1] = it->cross_start[c] + cursor[c + 1];
    }
}

/* Chunks (threads) wanted for a pass over n elements and the current pair list. */
static int wanted_chunks(const cdem_integrator *it, long n) {
    const long np = (long)it->nb.np;
    const int want = (np > it->par_min || n > it->par_min) ? omp_get_max_threads() : 1;
    return want < 1 ? 1 : (want > CDEM_MAX_CHUNKS ? CDEM_MAX_CHUNKS : want);
}

/* Pair forces, per-element sums and the second half kick, in one pass over the elements
 * (chunk_pass). Threaded: one parallel region, each thread evaluates the cross pairs into
 * its chunks (publishing its progress), then runs its chunks, waiting only where it meets a
 * cross pair not yet evaluated; every element sum has the same additions in the same order
 * for any chunking, so the bits do not depend on the thread count.
 * check_moved: first test whether some element moved more than half the skin since the
 * last build (cdem_neighbour_moved over each chunk, in the same parallel region, while the
 * positions are in the cache of the thread that just drifted them); if so nothing is
 * computed and 1 is returned: the caller rebuilds and calls again without the test. The
 * list must match the state's element count. Returns 0 when the forces were computed. */
static int forces_and_kick(cdem_integrator *it, cdem_state *s, int kick, int check_moved) {
    cdem_neighbour *nb = &it->nb;
    cdem_contact_law lawc; /* the law of this step, a local copy: provably not aliased by stores */
    cdem_contact_law_phase(&it->law, it->equilibrating, &lawc);
    const long n = (long)s->n;
    force_pass fp = {
        .law = &lawc,
        .kick = kick,
        .dt = it->dt,
        .hdt = 0.5 * it->dt,
        .c = cdem_integrator_damping(it),
        .g = it->gravity,
        .ob = it->overburden_force,
        .ef = it->confining_pressure * it->column_width * it->confining_factor,
        .exmid = it->edge_x_mid,
        .x = s->x,
        .y = s->y,
        .mass = s->mass,
        .kick_finish = (kick && update_kick(it, s)) ? it->kick_finish : NULL,
        .Rp = nb->R,
        .pi = nb->pi,
        .pj = nb->pj,
        .istart = nb->istart,
        .cls = nb->cls,
        .flags = s->flags,
        .hist = nb->hist,
        .xs = nb->xs,
        .pfx = nb->pfx,
        .pfy = nb->pfy,
        .fx = s->fx,
        .fy = s->fy,
        .vx = s->vx,
        .vy = s->vy,
    };
    const int nch = wanted_chunks(it, n);
    if (it->nchunk != nch || it->chunk_build != nb->n_builds || it->chunk_n != (size_t)n)
        make_chunks(it, s->flags, (size_t)n, nch);
    const int nchunk = it->nchunk;
    fp.nchunk = nchunk;
    fp.chunk_elem = it->chunk_elem;
    fp.cross_start = it->cross_start;
    fp.cross = it->cross;
    fp.it = it;
    fp.radius = it->unstable_guard ? s->radius : NULL;
    if (nchunk == 1) {
        if (check_moved && cdem_neighbour_moved(nb, s, 0, (size_t)n))
            return 1;
        chunk_pass(&fp, 0);
    } else {
        for (int c = 0; c < nchunk; c++)
            atomic_store_explicit(&it->cross_done[c].slot, 0, memory_order_relaxed); /* nothing
                                                evaluated yet: reset before every pass */
        int moved = 0;
        for (int c = 0; c < nchunk; c++)
            fp.seconds[c] = -1.0; /* no time: a thread that did not run */
#pragma omp parallel num_threads(nchunk)
        {
            const int t = omp_get_thread_num(), nt = omp_get_num_threads();
            int go = 1;
            if (check_moved) {
                int mine = 0;
                for (int c = t; c < nchunk; c += nt)
                    mine |= cdem_neighbour_moved(nb, s, (size_t)fp.chunk_elem[c],
                                                 (size_t)fp.chunk_elem[c + 1]);
                if (mine) {
#pragma omp atomic write
                    moved = 1;
                }
#pragma omp barrier
                int any;
#pragma omp atomic read
                any = moved;
                go = !any;
            }
            /* each thread first evaluates the cross pairs into its chunks, then runs them */
            if (go) {
                const double t0 = omp_get_wtime();
                for (int c = t; c < nchunk; c += nt)
                    cross_eval(&fp, c);
                for (int c = t; c < nchunk; c += nt)
                    chunk_pass(&fp, c);
                fp.seconds[t] = omp_get_wtime() - t0; /* for the load balance */
                if (nt != nchunk)
                    fp.seconds[t] = -1.0;
            }
        }
        if (moved)
            return 1;
        /* running means of the chunks' times (one chunk per thread), for the next cut */
        for (int c = 0; c < nchunk; c++) {
            const double sec = fp.seconds[c];
            if (!(sec >= 0.0))
                continue;
            it->chunk_time[c] = it->chunk_time[c] > 0.0 ? 0.9 * it->chunk_time[c] + 0.1 * sec : sec;
        }
    }
    it->unstable_index = -1;
    for (int c = 0; c < nchunk; c++)
        if (fp.unstable[c] >= 0) {
            it->unstable_index = fp.unstable[c]; /* the lowest index: chunks are in order */
            break;
        }
    return 0;
}

cdem_status cdem_integrator_prime(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    for (size_t i = 0; i < s->n; i++)
        if (is_free(s->flags[i]) && !(s->mass[i] > 0.0))
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "element id %d: mass = %g kg/m: free elements need a mass > 0",
                             (int)s->id[i], s->mass[i]);
    CDEM_TRY(check_finite(it, s, err));
    CDEM_TRY(rebuild(it, s, err));
    /* the first evaluation has no previous step: no tangential increment */
    const double dt = it->dt;
    it->dt = 0.0;
    forces_and_kick(it, s, 0, 0);
    it->dt = dt;
    return CDEM_OK;
}

/* First half kick and drift of the free elements. Threaded over the force pass's chunks
 * when they are current (each thread then moves the elements whose forces it computed and
 * whose rebuild test it makes next: they stay in its cache), else over equal ranges. */
static void drift(cdem_integrator *it, cdem_state *s) {
    const long n = (long)s->n;
    const double dt = it->dt, hdt = 0.5 * it->dt;
    double *restrict x = s->x, *restrict y = s->y, *restrict vx = s->vx, *restrict vy = s->vy;
    const double *restrict fx = s->fx, *restrict fy = s->fy, *restrict mass = s->mass;
    const uint32_t *restrict flags = s->flags;
    const double *restrict kd = update_kick(it, s) ? it->kick_drift : NULL;
    const int nchunk = wanted_chunks(it, n);
    const int chunked = nchunk > 1 && it->nchunk == nchunk && it->chunk_n == (size_t)n &&
                        it->chunk_build == it->nb.n_builds;
    const int32_t *ce = it->chunk_elem;
#pragma omp parallel num_threads(nchunk) if (nchunk > 1)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const int parts = chunked ? nchunk : nt;
        for (int c = t; c < parts; c += nt) {
            const long lo = chunked ? ce[c] : n * c / parts;
            const long hi = chunked ? ce[c + 1] : n * (c + 1) / parts;
            for (long i = lo; i < hi; i++) {
                if (flags[i] & CDEM_FLAGS_BOUNDARY)
                    continue;
                const double a = kd ? kd[i] : hdt / mass[i]; /* the same bits */
                const double hvx = vx[i] + a * fx[i], hvy = vy[i] + a * fy[i];
                vx[i] = hvx;
                vy[i] = hvy;
                x[i] += dt * hvx;
                y[i] += dt * hvy;
            }
        }
    }
}

cdem_status cdem_integrator_step(cdem_integrator *it, cdem_state *s, cdem_bc *bc, long k, double du,
                                 cdem_error *err) {
    it->n_removed_last = 0;
    if (it->nb.n_builds == 0)
        CDEM_TRY(cdem_integrator_prime(it, s, err));
    drift(it, s);
    it->step++;
    if (it->confining_pressure > 0.0)
        it->confining_factor = cdem_bc_confining_ramp(it->step, it->confining_equil);
    if (bc)
        CDEM_TRY(cdem_bc_apply(bc, s, k, du, it->dt, err));
    /* the rebuild test (cdem_neighbour_needs_rebuild) is made inside the force pass */
    if (it->nb.n == s->n && forces_and_kick(it, s, 1, 1) == 0)
        return CDEM_OK;
    CDEM_TRY(check_finite(it, s, err));
    CDEM_TRY(rebuild(it, s, err));
    forces_and_kick(it, s, 1, 0);
    return CDEM_OK;
}

/* Removes the elements marked 0 in it->keep (nrem of them) through the path escaping
 * elements take: ids to removed_ids, state compacted with histories kept, pair classes and
 * surface re-derived, and the forces of the new configuration evaluated without a
 * tangential increment or a kick (as in prime). */
static cdem_status remove_marked(cdem_integrator *it, cdem_state *s, size_t nrem, cdem_error *err) {
    CDEM_TRY(collect_removed(it, s, nrem, err));
    it->n_removed_last = nrem;
    CDEM_TRY(build_list(it, s, it->keep, err));
    const double dt = it->dt;
    it->dt = 0.0;
    forces_and_kick(it, s, 0, 0);
    it->dt = dt;
    return CDEM_OK;
}

cdem_status cdem_integrator_erode(cdem_integrator *it, cdem_state *s, double ymax, long *count,
                                  cdem_error *err) {
    if (count)
        *count = 0;
    it->n_removed_last = 0;
    CDEM_TRY(reserve_keep(it, s->n, err));
    size_t nrem = 0;
    for (size_t i = 0; i < s->n; i++) {
        const int out = !(s->flags[i] & CDEM_FLAGS_BOUNDARY) && s->y[i] > ymax;
        it->keep[i] = (unsigned char)!out;
        nrem += (size_t)out;
    }
    if (nrem == 0)
        return CDEM_OK;
    CDEM_TRY(remove_marked(it, s, nrem, err));
    it->n_removed += (long)nrem;
    if (count)
        *count = (long)nrem;
    return CDEM_OK;
}

cdem_status cdem_integrator_begin_deformation(cdem_integrator *it, cdem_state *s, cdem_bc *bc,
                                              size_t *n_removed, cdem_error *err) {
    *n_removed = 0;
    it->n_removed_last = 0;
    if (!bc)
        return CDEM_OK;
    if (it->nb.n_builds == 0)
        CDEM_TRY(cdem_integrator_prime(it, s, err));
    CDEM_TRY(reserve_keep(it, s->n, err));
    memset(it->keep, 1, s->n);
    size_t nrem = 0;
    CDEM_TRY(cdem_bc_begin_deformation(bc, s, it->keep, &nrem, err));
    if (nrem == 0)
        return CDEM_OK;
    size_t check = 0;
    for (size_t i = 0; i < s->n; i++)
        check += it->keep[i] == 0;
    if (check != nrem)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "boundary mode %s: begin_deformation reported %zu elements to remove "
                         "but marked %zu",
                         bc->ops->name, nrem, check);
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

cdem_status cdem_integrator_snapshot_put(const cdem_integrator *it, cdem_snapshot *snap,
                                         cdem_error *err) {
    const char *P = "it";
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "dt", it->dt, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "damping", it->damping, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "gravity", it->gravity, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "overburden_force", it->overburden_force, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "confining_pressure", it->confining_pressure, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "step", it->step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "boundary_forces", it->boundary_forces, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "bounds_set", it->bounds_set, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "escape_xmin", it->escape_xmin, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "escape_xmax", it->escape_xmax, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "escape_ymin", it->escape_ymin, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_removed", it->n_removed, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_surface", it->n_surface, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_edge", it->n_edge, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "confining_factor", it->confining_factor, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "edge_x_mid", it->edge_x_mid, err));
    CDEM_TRY(cdem_contact_snapshot_put(&it->law, snap, err));
    return cdem_neighbour_snapshot_put(&it->nb, snap, err);
}

cdem_status cdem_integrator_snapshot_get(cdem_integrator *it, const cdem_snapshot *snap,
                                         const cdem_state *s, cdem_error *err) {
    const char *P = "it";
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "dt", it->dt, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "damping", it->damping, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "gravity", it->gravity, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "overburden_force", it->overburden_force, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "confining_pressure", it->confining_pressure, err));
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
    CDEM_TRY(reserve_keep(it, s->n, err));
    CDEM_TRY(reserve_cross(it, err));
    CDEM_TRY(reserve_per_element(it, s->n, err));
    it->step = (long)step;
    it->boundary_forces = (int)bf;
    it->bounds_set = (int)bounds;
    it->escape_xmin = exmin;
    it->escape_xmax = exmax;
    it->escape_ymin = eymin;
    it->n_removed = (long)n_removed;
    it->n_surface = (long)n_surface;
    it->n_edge = (long)n_edge;
    it->confining_factor = cf;
    it->edge_x_mid = exmid;
    it->n_removed_last = 0;
    return CDEM_OK;
}
