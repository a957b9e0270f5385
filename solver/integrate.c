/* integrate: see integrate.h. The step is three passes over memory: (1) half kick + drift
 * of the free elements (fused with nothing else, so the boundary mode can move its
 * elements after it), (2) one pass over the pair slots computing each pair force once,
 * (3) one pass over the elements summing their slots through the CSR and finishing the
 * kick. Pass 2 and 3 are the hot loops; both are OpenMP schedule(static) with one writer
 * per output slot, so any thread count gives identical bits. */
#include "integrate.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Rebuilds between re-sorts of the state into cell order. */
#define RESORT_EVERY 20
/* Default of cdem_integrator.par_min: loops shorter than this run on one thread. A step of
 * the default model (~2500 elements, ~5000 pairs) takes ~0.1 ms, comparable to the cost of
 * an OpenMP barrier when the cores are shared, so small models stay serial. */
#define PAR_MIN_DEFAULT 16384

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
    it->par_min = PAR_MIN_DEFAULT;
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
        xmin = fmin(xmin, s->x[i]);
        xmax = fmax(xmax, s->x[i]);
        ymin = fmin(ymin, s->y[i]);
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

static cdem_status rebuild(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    size_t nrem = 0;
    CDEM_TRY(find_escapes(it, s, &nrem, err));
    it->n_removed_last = nrem;
    it->n_removed += (long)nrem;
    CDEM_TRY(cdem_neighbour_build(&it->nb, s, nrem ? it->keep : NULL, 0, err));
    cdem_integrator_classify(it, s);
    if (it->overburden_force > 0.0)
        CDEM_TRY(cdem_integrator_find_surface(it, s, err));
    if (it->confining_pressure > 0.0)
        CDEM_TRY(cdem_integrator_find_edges(it, s, err));
    return CDEM_OK;
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
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        size_t b = (size_t)((s->y[i] - ymin) / w);
        if (b >= nb)
            b = nb - 1;
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
        int32_t *q = realloc(it->col_top, c * sizeof *q);
        if (!q)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu columns)", c);
        it->col_top = q;
        it->colcap = c;
    }
    for (size_t c = 0; c < ncol; c++)
        it->col_top[c] = -1;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        size_t c = (size_t)((s->x[i] - xmin) / w);
        if (c >= ncol)
            c = ncol - 1;
        const int32_t b = it->col_top[c];
        if (b < 0 || s->y[i] > s->y[b])
            it->col_top[c] = (int32_t)i;
    }
    long count = 0;
    for (size_t c = 0; c < ncol; c++) {
        if (it->col_top[c] < 0)
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

/* Force of pair p on pi[p] into its slot (zero when it does not touch). */
static inline void pair_force(const cdem_contact_law *law, long p, const double *restrict x,
                              const double *restrict y, const double *restrict vx,
                              const double *restrict vy, const int32_t *restrict pi,
                              const int32_t *restrict pj, const double *restrict Rp,
                              const uint8_t *restrict cls, uint8_t *restrict hist,
                              double *restrict xs, double *restrict pfx, double *restrict pfy,
                              double dt) {
    const int32_t i = pi[p], j = pj[p];
    const double dx = x[j] - x[i], dy = y[j] - y[i];
    const double R = Rp[p];
    const uint8_t h = hist[p];
    if (!(h & CDEM_PAIR_BONDED) && dx * dx + dy * dy >= R * R) {
        /* the common case: a list pair that does not touch */
        pfx[p] = 0.0;
        pfy[p] = 0.0;
        if (h) {
            hist[p] = 0;
            xs[p] = 0.0;
        }
        return;
    }
    cdem_contact_eval(law, cls[p], dx, dy, R, vx[j] - vx[i], vy[j] - vy[i], dt, &xs[p], &hist[p],
                      &pfx[p], &pfy[p]);
}

/* Finishes element i from its contact-force sum (sx, sy): gravity, the damped second half
 * kick (when kick), and the total force stored in fx, fy. */
static inline void finish_element(long i, double sx, double sy, const double *restrict mass,
                                  const uint32_t *restrict flags, double *restrict vxw,
                                  double *restrict vyw, double *restrict fx, double *restrict fy,
                                  double hdt, double c, double g, double ob, int kick,
                                  const double *restrict x, double ef, double exmid,
                                  const double *restrict y, const double *restrict aff) {
    const double m = mass[i];
    sy -= m * g + ((flags[i] & CDEM_FLAG_SURFACE) ? ob : 0.0);
    if (flags[i] & CDEM_FLAG_BIAXIAL_EDGE)
        sx += x[i] < exmid ? ef : -ef;
    /* damping acts on v - v_aff (v_aff = 0 exactly unless affine damping is on) */
    const double rx = aff[0] * (x[i] - aff[2]), ry = aff[1] * (y[i] - aff[3]);
    if (kick) {
        /* v = (v_half + hdt/m (F + c v_aff)) / (1 + c hdt/m) with a single division */
        const double inv = 1.0 / (m + c * hdt);
        vxw[i] = (m * vxw[i] + hdt * (sx + c * rx)) * inv;
        vyw[i] = (m * vyw[i] + hdt * (sy + c * ry)) * inv;
    }
    fx[i] = sx - c * (vxw[i] - rx);
    fy[i] = sy - c * (vyw[i] - ry);
}

/* Affine damping: the least-squares homogeneous strain-rate field of the free elements'
 * current (mid-step) velocities, v_aff = (ax (x - xc), ay (y - yc)), xc, yc their mean
 * position. Serial sums in element order: reproducible for any thread count. */
static void fit_affine(cdem_integrator *it, const cdem_state *s) {
    double n = 0.0, sx = 0.0, sy = 0.0;
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY)) {
            n += 1.0;
            sx += s->x[i];
            sy += s->y[i];
        }
    it->aff[0] = it->aff[1] = it->aff[2] = it->aff[3] = 0.0;
    if (n < 2.0)
        return;
    const double xc = sx / n, yc = sy / n;
    double sxx = 0.0, syy = 0.0, svx = 0.0, svy = 0.0;
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY)) {
            const double dx = s->x[i] - xc, dy = s->y[i] - yc;
            sxx += dx * dx;
            syy += dy * dy;
            svx += s->vx[i] * dx;
            svy += s->vy[i] * dy;
        }
    it->aff[0] = sxx > 0.0 ? svx / sxx : 0.0;
    it->aff[1] = syy > 0.0 ? svy / syy : 0.0;
    it->aff[2] = xc;
    it->aff[3] = yc;
}

/* Pair forces, per-element sums and the second half kick. Two paths give the same bits:
 *  - serial: each pair force is added to its two elements as it is computed (a scatter in
 *    ascending pair order), then one streaming pass finishes the elements;
 *  - threaded: pair forces go to their slots (one writer each), then each element merges
 *    its pi range and its pj list in ascending pair order, i.e. the same additions in the
 *    same order as the scatter. */
static void forces_and_kick(cdem_integrator *it, cdem_state *s, int kick) {
    cdem_neighbour *nb = &it->nb;
    const cdem_contact_law lawc = it->law; /* a local copy: provably not aliased by stores */
    const cdem_contact_law *law = &lawc;
    const double dt = it->dt;
    const long np = (long)nb->np, n = (long)s->n;
    const double *restrict x = s->x, *restrict y = s->y;
    const int32_t *restrict pi = nb->pi, *restrict pj = nb->pj;
    const double *restrict Rp = nb->R;
    const uint8_t *restrict cls = nb->cls;
    uint8_t *restrict hist = nb->hist;
    double *restrict xs = nb->xs, *restrict pfx = nb->pfx, *restrict pfy = nb->pfy;
    const double *restrict mass = s->mass;
    const uint32_t *restrict flags = s->flags;
    double *restrict fx = s->fx, *restrict fy = s->fy;
    double *restrict vxw = s->vx, *restrict vyw = s->vy;
    const double hdt = 0.5 * dt, c = it->damping, g = it->gravity, ob = it->overburden_force;
    const double ef = it->confining_pressure * it->column_width * it->confining_factor;
    const double exmid = it->edge_x_mid;
    const double aff[4] = {it->aff[0], it->aff[1], it->aff[2], it->aff[3]};
    const int threaded = (np > it->par_min || n > it->par_min) && omp_get_max_threads() > 1;

    if (!threaded) {
        memset(fx, 0, (size_t)n * sizeof *fx);
        memset(fy, 0, (size_t)n * sizeof *fy);
        for (long p = 0; p < np; p++) {
            pair_force(law, p, x, y, vxw, vyw, pi, pj, Rp, cls, hist, xs, pfx, pfy, dt);
            const double ffx = pfx[p], ffy = pfy[p];
            fx[pi[p]] += ffx;
            fy[pi[p]] += ffy;
            fx[pj[p]] -= ffx;
            fy[pj[p]] -= ffy;
        }
        for (long i = 0; i < n; i++)
            if (!(flags[i] & CDEM_FLAGS_BOUNDARY))
                finish_element(i, fx[i], fy[i], mass, flags, vxw, vyw, fx, fy, hdt, c, g, ob, kick,
                               x, ef, exmid, y, aff);
        return;
    }

#pragma omp parallel for schedule(static)
    for (long p = 0; p < np; p++)
        pair_force(law, p, x, y, vxw, vyw, pi, pj, Rp, cls, hist, xs, pfx, pfy, dt);

    const int32_t *restrict istart = nb->istart, *restrict jstart = nb->jstart;
    const int32_t *restrict jslot = nb->jslot;
    const int want_boundary = it->boundary_forces || !kick;
#pragma omp parallel for schedule(static)
    for (long i = 0; i < n; i++) {
        const int boundary = (flags[i] & CDEM_FLAGS_BOUNDARY) != 0;
        if (boundary && !want_boundary)
            continue; /* not integrated; its force only matters for reports */
        double sx = 0.0, sy = 0.0;
        int32_t a = istart[i], b = jstart[i];
        const int32_t ae = istart[i + 1], be = jstart[i + 1];
        while (a < ae || b < be) {
            if (b >= be || (a < ae && a < jslot[b])) {
                sx += pfx[a];
                sy += pfy[a];
                a++;
            } else {
                sx -= pfx[jslot[b]];
                sy -= pfy[jslot[b]];
                b++;
            }
        }
        if (boundary) {
            fx[i] = sx;
            fy[i] = sy;
            continue;
        }
        finish_element(i, sx, sy, mass, flags, vxw, vyw, fx, fy, hdt, c, g, ob, kick, x, ef, exmid,
                       y, aff);
    }
}

cdem_status cdem_integrator_prime(cdem_integrator *it, cdem_state *s, cdem_error *err) {
    for (size_t i = 0; i < s->n; i++)
        if (is_free(s->flags[i]) && !(s->mass[i] > 0.0))
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "element id %d: mass = %g kg/m: free elements need a mass > 0",
                             (int)s->id[i], s->mass[i]);
    CDEM_TRY(check_finite(it, s, err));
    CDEM_TRY(rebuild(it, s, err));
    if (it->affine_damping)
        fit_affine(it, s);
    else
        it->aff[0] = it->aff[1] = 0.0;
    /* the first evaluation has no previous step: no tangential increment */
    const double dt = it->dt;
    it->dt = 0.0;
    forces_and_kick(it, s, 0);
    it->dt = dt;
    return CDEM_OK;
}

cdem_status cdem_integrator_step(cdem_integrator *it, cdem_state *s, cdem_bc *bc, long k, double du,
                                 cdem_error *err) {
    it->n_removed_last = 0;
    if (it->nb.n_builds == 0)
        CDEM_TRY(cdem_integrator_prime(it, s, err));
    const long n = (long)s->n;
    const double dt = it->dt, hdt = 0.5 * it->dt;
    {
        double *restrict x = s->x, *restrict y = s->y, *restrict vx = s->vx, *restrict vy = s->vy;
        const double *restrict fx = s->fx, *restrict fy = s->fy, *restrict mass = s->mass;
        const uint32_t *restrict flags = s->flags;
#pragma omp parallel for schedule(static) if (n > it->par_min)
        for (long i = 0; i < n; i++) {
            if (flags[i] & CDEM_FLAGS_BOUNDARY)
                continue;
            const double a = hdt / mass[i];
            const double hvx = vx[i] + a * fx[i], hvy = vy[i] + a * fy[i];
            vx[i] = hvx;
            vy[i] = hvy;
            x[i] += dt * hvx;
            y[i] += dt * hvy;
        }
    }
    it->step++;
    if (it->confining_pressure > 0.0)
        it->confining_factor = cdem_bc_confining_ramp(it->step, it->confining_equil);
    if (bc)
        CDEM_TRY(cdem_bc_apply(bc, s, k, du, dt, err));
    if (cdem_neighbour_needs_rebuild(&it->nb, s)) {
        CDEM_TRY(check_finite(it, s, err));
        CDEM_TRY(rebuild(it, s, err));
    }
    if (it->affine_damping)
        fit_affine(it, s);
    else
        it->aff[0] = it->aff[1] = 0.0; /* plain damping (also after switching it off) */
    forces_and_kick(it, s, 1);
    return CDEM_OK;
}

/* Removes the elements marked 0 in it->keep (nrem of them) through the path escaping
 * elements take: ids to removed_ids, state compacted with histories kept, pair classes and
 * surface re-derived, and the forces of the new configuration evaluated without a
 * tangential increment or a kick (as in prime). */
static cdem_status remove_marked(cdem_integrator *it, cdem_state *s, size_t nrem, cdem_error *err) {
    CDEM_TRY(collect_removed(it, s, nrem, err));
    it->n_removed_last = nrem;
    CDEM_TRY(cdem_neighbour_build(&it->nb, s, it->keep, 0, err));
    cdem_integrator_classify(it, s);
    if (it->overburden_force > 0.0)
        CDEM_TRY(cdem_integrator_find_surface(it, s, err));
    if (it->confining_pressure > 0.0)
        CDEM_TRY(cdem_integrator_find_edges(it, s, err));
    const double dt = it->dt;
    it->dt = 0.0;
    forces_and_kick(it, s, 0);
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
    long count = 0;
    for (size_t p = 0; p < it->nb.np; p++) {
        if ((it->nb.hist[p] & CDEM_PAIR_TOUCH) && it->nb.cls[p] != CDEM_CLASS_SLIP) {
            it->nb.hist[p] |= flag;
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
