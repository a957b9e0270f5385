/* strain: see strain.h. The fit works on twelve running sums (n, the first and second
 * moments of X and their products with ux and uy), solved in closed form by the adjugate of
 * the symmetric 3x3 normal matrix; test_strain checks it against gsl_multifit_linear.
 * Coordinates are divided by the search radius before summing so the matrix entries are O(1)
 * and the degeneracy threshold is scale-free. The measures avoid cancellation: S - 1 is
 * computed as (lambda - 1) / (S + 1) from lambda - 1 formed directly from G, and the dilation
 * as det F - 1 = gxx + gyy + gxx gyy - gxy gyx. */
#include "strain.h"

#include "grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { S_N, S_X, S_Y, S_XX, S_XY, S_YY, S_U, S_XU, S_YU, S_V, S_XV, S_YV, S_COUNT };

/* Solves the normal equations from the sums; X, Y were divided by `scale`. */
static int fit_from_sums(const double *s, double scale, double g[4], double t[2]) {
    const double a00 = s[S_N], a01 = s[S_X], a02 = s[S_Y], a11 = s[S_XX], a12 = s[S_XY],
                 a22 = s[S_YY];
    const double c00 = a11 * a22 - a12 * a12, c01 = a02 * a12 - a01 * a22,
                 c02 = a01 * a12 - a11 * a02, c11 = a00 * a22 - a02 * a02,
                 c12 = a01 * a02 - a00 * a12, c22 = a00 * a11 - a01 * a01;
    const double det = a00 * c00 + a01 * c01 + a02 * c02;
    if (a00 < 3.0 || !(det > 1e-10 * a00 * a00 * a00)) {
        g[0] = g[1] = g[2] = g[3] = NAN;
        if (t)
            t[0] = t[1] = NAN;
        return 0;
    }
    const double inv = 1.0 / det;
    const double bu0 = s[S_U], bu1 = s[S_XU], bu2 = s[S_YU];
    const double bv0 = s[S_V], bv1 = s[S_XV], bv2 = s[S_YV];
    g[0] = (c01 * bu0 + c11 * bu1 + c12 * bu2) * inv / scale;
    g[1] = (c02 * bu0 + c12 * bu1 + c22 * bu2) * inv / scale;
    g[2] = (c01 * bv0 + c11 * bv1 + c12 * bv2) * inv / scale;
    g[3] = (c02 * bv0 + c12 * bv1 + c22 * bv2) * inv / scale;
    if (t) {
        t[0] = (c00 * bu0 + c01 * bu1 + c02 * bu2) * inv;
        t[1] = (c00 * bv0 + c01 * bv1 + c02 * bv2) * inv;
    }
    return 1;
}

static inline void add_point(double *s, double X, double Y, double u, double v) {
    s[S_N] += 1.0;
    s[S_X] += X;
    s[S_Y] += Y;
    s[S_XX] += X * X;
    s[S_XY] += X * Y;
    s[S_YY] += Y * Y;
    s[S_U] += u;
    s[S_XU] += X * u;
    s[S_YU] += Y * u;
    s[S_V] += v;
    s[S_XV] += X * v;
    s[S_YV] += Y * v;
}

int cdem_strain_fit(size_t m, const double *X, const double *Y, const double *ux, const double *uy,
                    double g[4], double t[2]) {
    double scale = 0.0;
    for (size_t k = 0; k < m; k++)
        scale = fmax(scale, fmax(fabs(X[k]), fabs(Y[k])));
    if (!(scale > 0.0) || !isfinite(scale))
        scale = 1.0;
    double s[S_COUNT] = {0};
    for (size_t k = 0; k < m; k++)
        add_point(s, X[k] / scale, Y[k] / scale, ux[k], uy[k]);
    return fit_from_sums(s, scale, g, t);
}

void cdem_strain_measures_from_gradient(const double g[4], cdem_strain_measures *m) {
    const double gxx = g[0], gxy = g[1], gyx = g[2], gyy = g[3];
    const double detF1 = gxx + gyy + gxx * gyy - gxy * gyx; /* det F - 1 */
    if (!isfinite(gxx) || !isfinite(gxy) || !isfinite(gyx) || !isfinite(gyy) || !(detF1 > -1.0)) {
        m->e1 = m->e3_neg = m->max_shear = m->dilation = m->rotation = m->angle1 = NAN;
        return;
    }
    /* C - I, from F = I + G. */
    const double c11m = 2.0 * gxx + gxx * gxx + gyx * gyx;
    const double c22m = 2.0 * gyy + gyy * gyy + gxy * gxy;
    const double c12 = (1.0 + gxx) * gxy + gyx * (1.0 + gyy);
    const double p = 0.5 * (c11m + c22m), d = 0.5 * (c11m - c22m);
    const double r = hypot(d, c12);
    const double l1m = p + r, l3m = p - r; /* lambda - 1 */
    const double S1 = sqrt(1.0 + l1m);
    const double detF = 1.0 + detF1; /* = S1 S3 */
    const double S3 = detF / S1;
    m->e1 = l1m / (S1 + 1.0);
    m->e3_neg = -l3m / (S3 + 1.0);
    m->max_shear = r / detF; /* (l1 - l3) / (2 sqrt(l1 l3)) = 2r / (2 S1 S3) */
    m->dilation = detF1;
    m->rotation = 0.5 * (gxy - gyx);
    /* S1 direction in the deformed frame: eigenvector of B = F F^T. */
    const double b11 = (1.0 + gxx) * (1.0 + gxx) + gxy * gxy;
    const double b22 = gyx * gyx + (1.0 + gyy) * (1.0 + gyy);
    const double b12 = (1.0 + gxx) * gyx + gxy * (1.0 + gyy);
    if (r <= 1e-13 * (1.0 + fabs(p))) {
        m->angle1 = NAN;
    } else {
        double a = 0.5 * atan2(2.0 * b12, b11 - b22) * (180.0 / M_PI);
        if (a <= -90.0)
            a += 180.0;
        m->angle1 = a;
    }
}

double cdem_strain_max_radius(const cdem_state *s) {
    double r = 0.0;
    for (size_t i = 0; i < s->n; i++)
        if (isfinite(s->radius[i]) && s->radius[i] > r)
            r = s->radius[i];
    return r;
}

cdem_status cdem_strain_gradients(const cdem_state *ref, const cdem_state *cur,
                                  const unsigned char *select, double radius, double *grad,
                                  cdem_error *err) {
    for (size_t i = 0; i < 4 * cur->n; i++)
        grad[i] = NAN;
    if (!(radius > 0.0))
        radius = 2.0 * cdem_strain_max_radius(ref);
    if (!(radius > 0.0) || !isfinite(radius) || ref->n == 0 || cur->n == 0)
        return CDEM_OK; /* nothing can be fitted: every value stays undefined */

    cdem_id_map cur_map, ref_map;
    CDEM_TRY(cdem_id_map_build(&cur_map, cur, err));
    cdem_status st = cdem_id_map_build(&ref_map, ref, err);
    if (st != CDEM_OK) {
        cdem_id_map_free(&cur_map);
        return st;
    }
    /* Per reference element: its slot in cur (SIZE_MAX when gone) and its displacement. */
    size_t *to_cur = malloc(ref->n * sizeof *to_cur);
    double *ux = malloc(ref->n * sizeof *ux), *uy = malloc(ref->n * sizeof *uy);
    unsigned char *use = malloc(ref->n);
    cdem_grid_index grid = {0};
    if (!to_cur || !ux || !uy || !use) {
        st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "strain: out of memory for %zu elements", ref->n);
        goto done;
    }
    for (size_t j = 0; j < ref->n; j++) {
        size_t c = cdem_id_map_find(&cur_map, ref->id[j]);
        to_cur[j] = c;
        use[j] = 0;
        ux[j] = uy[j] = NAN;
        if (c == SIZE_MAX || (ref->flags[j] & CDEM_FLAGS_BOUNDARY))
            continue;
        ux[j] = cur->x[c] - ref->x[j];
        uy[j] = cur->y[c] - ref->y[j];
        use[j] = isfinite(ux[j]) && isfinite(uy[j]);
    }
    st = cdem_grid_index_build(&grid, ref->x, ref->y, ref->n, use, radius, err);
    if (st != CDEM_OK)
        goto done;

    const double r2 = radius * radius, inv_h = 1.0 / radius;
    const long ncur = (long)cur->n;
#pragma omp parallel for schedule(static)
    for (long ii = 0; ii < ncur; ii++) {
        const size_t i = (size_t)ii;
        if ((select && !select[i]) || (cur->flags[i] & CDEM_FLAGS_BOUNDARY))
            continue;
        const size_t r = cdem_id_map_find(&ref_map, cur->id[i]);
        if (r == SIZE_MAX || !use[r])
            continue;
        const double px = ref->x[r], py = ref->y[r];
        cdem_grid_box box;
        if (!cdem_grid_index_range(&grid, px, py, radius, &box))
            continue;
        double s[S_COUNT] = {0};
        for (size_t cy = box.y_lo; cy <= box.y_hi; cy++)
            for (size_t cx = box.x_lo; cx <= box.x_hi; cx++) {
                const size_t c = cy * grid.grid.nx + cx;
                for (int32_t q = grid.start[c]; q < grid.start[c + 1]; q++) {
                    const size_t j = (size_t)grid.items[q];
                    const double dx = ref->x[j] - px, dy = ref->y[j] - py;
                    if (dx * dx + dy * dy > r2)
                        continue;
                    add_point(s, dx * inv_h, dy * inv_h, ux[j], uy[j]);
                }
            }
        fit_from_sums(s, radius, grad + 4 * i, NULL);
    }
done:
    cdem_grid_index_free(&grid);
    free(to_cur);
    free(ux);
    free(uy);
    free(use);
    cdem_id_map_free(&cur_map);
    cdem_id_map_free(&ref_map);
    return st;
}

cdem_status cdem_strain_compute(const cdem_state *ref, const cdem_state *cur,
                                const unsigned char *select, double radius,
                                cdem_strain_measures *out, cdem_error *err) {
    double *grad = malloc((4 * cur->n + 1) * sizeof *grad);
    if (!grad)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "strain: out of memory for %zu elements", cur->n);
    cdem_status st = cdem_strain_gradients(ref, cur, select, radius, grad, err);
    if (st == CDEM_OK) {
        const long n = (long)cur->n;
#pragma omp parallel for schedule(static)
        for (long i = 0; i < n; i++)
            cdem_strain_measures_from_gradient(grad + 4 * i, &out[i]);
    }
    free(grad);
    return st;
}

/* ---------------------------------------------------------------- cumulative strain */

void cdem_strain_cum_init(cdem_strain_cum *c) {
    memset(c, 0, sizeof *c);
    c->last_number = -1;
}

void cdem_strain_cum_free(cdem_strain_cum *c) {
    if (!c)
        return;
    free(c->sum);
    free(c->count);
    cdem_strain_cum_init(c);
}

void cdem_strain_cum_reset(cdem_strain_cum *c) {
    if (c->sum)
        memset(c->sum, 0, c->cap * CDEM_STRAIN_NMEASURES * sizeof *c->sum);
    if (c->count)
        memset(c->count, 0, c->cap * sizeof *c->count);
    c->last_number = -1;
}

static double *field(cdem_strain_measures *m, int k) {
    double *f[CDEM_STRAIN_NMEASURES] = {&m->e1,       &m->e3_neg,   &m->max_shear,
                                        &m->dilation, &m->rotation, &m->angle1};
    return f[k];
}

cdem_status cdem_strain_cum_add(cdem_strain_cum *c, const cdem_state *cur,
                                const cdem_strain_measures *pair, cdem_error *err) {
    size_t need = 0;
    for (size_t i = 0; i < cur->n; i++) {
        if (cur->id[i] < 0)
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "cumulative strain: element %zu has negative id %d", i,
                             (int)cur->id[i]);
        if ((size_t)cur->id[i] + 1 > need)
            need = (size_t)cur->id[i] + 1;
    }
    if (need > c->cap) {
        size_t cap = c->cap ? c->cap : 64;
        while (cap < need)
            cap += cap / 2 + 1;
        double *s = realloc(c->sum, cap * CDEM_STRAIN_NMEASURES * sizeof *s);
        if (!s)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "cumulative strain: out of memory for %zu ids",
                             cap);
        c->sum = s;
        unsigned *k = realloc(c->count, cap * sizeof *k);
        if (!k)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "cumulative strain: out of memory for %zu ids",
                             cap);
        c->count = k;
        memset(c->sum + c->cap * CDEM_STRAIN_NMEASURES, 0,
               (cap - c->cap) * CDEM_STRAIN_NMEASURES * sizeof *s);
        memset(c->count + c->cap, 0, (cap - c->cap) * sizeof *k);
        c->cap = cap;
    }
    for (size_t i = 0; i < cur->n; i++) {
        cdem_strain_measures m = pair[i];
        if (!isfinite(m.e1))
            continue;
        double *s = c->sum + (size_t)cur->id[i] * CDEM_STRAIN_NMEASURES;
        for (int k = 0; k < CDEM_STRAIN_NMEASURES - 1; k++)
            s[k] += *field(&m, k);
        c->count[cur->id[i]]++;
    }
    return CDEM_OK;
}

void cdem_strain_cum_get(const cdem_strain_cum *c, const cdem_state *s, int zero_if_none,
                         cdem_strain_measures *out) {
    for (size_t i = 0; i < s->n; i++) {
        cdem_strain_measures *m = &out[i];
        const int32_t id = s->id[i];
        const int wall = (s->flags[i] & CDEM_FLAGS_BOUNDARY) != 0;
        const int has = id >= 0 && (size_t)id < c->cap && c->count[id] > 0;
        for (int k = 0; k < CDEM_STRAIN_NMEASURES; k++) {
            double v = NAN;
            if (!wall && k < CDEM_STRAIN_NMEASURES - 1) {
                if (has)
                    v = c->sum[(size_t)id * CDEM_STRAIN_NMEASURES + k];
                else if (zero_if_none)
                    v = 0.0;
            }
            *field(m, k) = v;
        }
    }
}

void cdem_stress_principal_from(double sxx, double syy, double sxy, cdem_stress_principal *p) {
    const double c = 0.5 * (sxx + syy), d = 0.5 * (sxx - syy);
    const double r = hypot(d, sxy);
    p->sigma1 = c + r;
    p->sigma3 = c - r;
    p->max_shear = r;
    if (!isfinite(r) || r <= 1e-14 * fabs(c)) {
        p->angle1 = NAN;
    } else {
        double a = 0.5 * atan2(2.0 * sxy, sxx - syy) * (180.0 / M_PI);
        if (a <= -90.0)
            a += 180.0;
        p->angle1 = a;
    }
}
