/* repose: see repose.h. */
#include "repose.h"
#include "surface.h"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fit.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double rad2deg = 180.0 / 3.14159265358979323846;

/* Angle (deg) of the least-squares line through the k >= 2 points (x, y). */
static double fit_angle(const double *x, const double *y, size_t k) {
    double c0, c1, c00, c01, c11, ss;
    gsl_fit_linear(x, 1, y, 1, k, &c0, &c1, &c00, &c01, &c11, &ss);
    return atan(fabs(c1)) * rad2deg;
}

/* The quality measures of flank f, fitted through its k points (x ascending); upper_first:
 * 1 when the first points are the upper ones (the right flank). */
static void flank_quality(cdem_repose_flank *f, const double *x, const double *y, size_t k,
                          double cov11, int upper_first, double r_max) {
    f->angle_ci_deg = NAN;
    f->angle_upper_deg = f->angle_lower_deg = NAN;
    if (k >= 3) {
        double t = gsl_cdf_tdist_Pinv(0.975, (double)(k - 2));
        f->angle_ci_deg = t * sqrt(cov11) / (1.0 + f->slope * f->slope) * rad2deg;
    }
    if (k >= 4) { /* halves in x order, sharing the middle point when k is odd */
        size_t h1 = (k + 1) / 2, h0 = k / 2;
        double a = fit_angle(x, y, h1), b = fit_angle(x + h0, y + h0, k - h0);
        f->angle_upper_deg = upper_first ? a : b;
        f->angle_lower_deg = upper_first ? b : a;
    }
    f->poor = 0;
    if (k < CDEM_REPOSE_MIN_COLUMNS)
        f->poor |= CDEM_REPOSE_FEW;
    if (!(f->angle_ci_deg <= CDEM_REPOSE_MAX_CI_DEG))
        f->poor |= CDEM_REPOSE_UNCERTAIN;
    if (f->residual_rms > CDEM_REPOSE_MAX_RMS_RADII * r_max)
        f->poor |= CDEM_REPOSE_ROUGH;
    if (fabs(f->angle_upper_deg - f->angle_lower_deg) > CDEM_REPOSE_MAX_BEND_DEG)
        f->poor |= CDEM_REPOSE_CURVED;
}

cdem_status cdem_repose_measure(const cdem_state *s, cdem_repose_result *res, cdem_error *err) {
    if (!s || !res)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "repose: NULL argument");
    memset(res, 0, sizeof *res);
    double rmax = 0, xmin = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < s->n; i++)
        if (cdem_surface_is_free(s, i)) {
            rmax = fmax(rmax, s->radius[i]);
            xmin = fmin(xmin, s->x[i]);
            xmax = fmax(xmax, s->x[i]);
        }
    if (!(rmax > 0))
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "repose: the state has no free (non-wall) elements (%zu elements)", s->n);
    double cw = 2.0 * rmax;
    double span = (xmax - xmin) / cw;
    if (span > 1e7)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "repose: free elements span %g m, over 1e7 columns of %g m", xmax - xmin,
                         cw);
    size_t nc = (size_t)floor(span) + 1;
    size_t *top = malloc(nc * sizeof *top);
    double *fx = malloc(nc * sizeof *fx), *fy = malloc(nc * sizeof *fy);
    if (!top || !fx || !fy) {
        free(top);
        free(fx);
        free(fy);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "repose: no memory for %zu columns", nc);
    }
    cdem_surface_column_tops(s, xmin, cw, nc, -INFINITY, INFINITY, top);
    double lo = INFINITY, hi = -INFINITY;
    size_t crest = SIZE_MAX;
    for (size_t c = 0; c < nc; c++)
        if (top[c] != SIZE_MAX) {
            double t = s->y[top[c]] + s->radius[top[c]];
            lo = fmin(lo, t);
            if (t > hi) {
                hi = t;
                crest = top[c];
            }
            res->n_columns++;
        }
    res->crest_x = s->x[crest];
    res->column_width = cw;
    res->r_max = rmax;
    double t_lo = lo + 0.1 * (hi - lo), t_hi = lo + 0.9 * (hi - lo);
    size_t m = 0, m_left = 0;
    for (int side = 0; side < 2; side++) /* left flank first, then the right one */
        for (size_t c = 0; c < nc; c++)
            if (top[c] != SIZE_MAX) {
                double t = s->y[top[c]] + s->radius[top[c]];
                int left = s->x[top[c]] < res->crest_x;
                if (t > t_lo && t < t_hi && left == !side) {
                    fx[m] = s->x[top[c]];
                    fy[m] = t;
                    m++;
                    m_left += left;
                }
            }
    free(top);
    double wsum = 0, asum = 0;
    for (int side = 0; side < 2; side++) {
        size_t k0 = side ? m_left : 0, k = side ? m - m_left : m_left;
        if (k < 2 || 4 * k < m)
            continue;
        cdem_repose_flank *f = &res->flank[side];
        double c0, c1, c00, c01, c11, ss;
        gsl_fit_linear(fx + k0, 1, fy + k0, 1, k, &c0, &c1, &c00, &c01, &c11, &ss);
        f->slope = c1;
        f->intercept = c0;
        f->angle_deg = atan(fabs(c1)) * rad2deg;
        f->x_first = fx[k0];
        f->x_last = fx[k0 + k - 1];
        f->n = k;
        f->residual_rms = sqrt(ss / k);
        flank_quality(f, fx + k0, fy + k0, k, c11, side, rmax);
        res->poor |= f->poor;
        res->n_fitted += k;
        wsum += k;
        asum += k * f->angle_deg;
    }
    cdem_status st = CDEM_OK;
    if (res->n_fitted < 2)
        st = CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                       "repose: only %zu surface column(s) of %g m lie on a slope (tops between "
                       "10 %% and 90 %% of the height drop %g m); need at least 2 on one side of "
                       "the crest",
                       m, cw, hi - lo);
    else
        res->angle_deg = asum / wsum;
    free(fx);
    free(fy);
    return st;
}

void cdem_repose_poor_text(const cdem_repose_flank *f, double r_max, char *buf, size_t n) {
    if (!n)
        return;
    buf[0] = 0;
    size_t used = 0;
    const char *sep = "";
#define PUT(...)                                                                                   \
    do {                                                                                           \
        if (used < n) {                                                                            \
            int w = snprintf(buf + used, n - used, __VA_ARGS__);                                   \
            used += w > 0 ? (size_t)w : 0;                                                         \
        }                                                                                          \
        sep = "; ";                                                                                \
    } while (0)
    if (f->poor & CDEM_REPOSE_CURVED)
        PUT("%sthe slope is curved: upper half %.1f deg, lower half %.1f deg (more than %g deg "
            "apart)",
            sep, f->angle_upper_deg, f->angle_lower_deg, CDEM_REPOSE_MAX_BEND_DEG);
    if (f->poor & CDEM_REPOSE_ROUGH)
        PUT("%srms misfit %.4g m, over %g x the largest radius %.4g m", sep, f->residual_rms,
            CDEM_REPOSE_MAX_RMS_RADII, r_max);
    if (f->poor & CDEM_REPOSE_UNCERTAIN)
        PUT("%sangle uncertain by +- %.2g deg (95 %%), over %g", sep, f->angle_ci_deg,
            CDEM_REPOSE_MAX_CI_DEG);
    if (f->poor & CDEM_REPOSE_FEW)
        PUT("%sonly %zu columns on the slope, fewer than %d", sep, f->n, CDEM_REPOSE_MIN_COLUMNS);
#undef PUT
}

cdem_status cdem_repose_motion_between(const cdem_state *a, const cdem_state *b,
                                       cdem_repose_motion *m, cdem_error *err) {
    if (!a || !b || !m)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "repose motion: NULL argument");
    memset(m, 0, sizeof *m);
    int32_t id_max = -1;
    for (int k = 0; k < 2; k++) {
        const cdem_state *s = k ? b : a;
        for (size_t i = 0; i < s->n; i++) {
            if (!cdem_surface_is_free(s, i))
                continue;
            if (s->id[i] < 0)
                return CDEM_FAIL(err, CDEM_ERR_INVALID,
                                 "repose motion: element %zu has id %d: ids must be >= 0", i,
                                 (int)s->id[i]);
            id_max = s->id[i] > id_max ? s->id[i] : id_max;
            *(k ? &m->n_after : &m->n_before) += 1;
        }
    }
    if (id_max < 0)
        return CDEM_OK;
    size_t *where = malloc(((size_t)id_max + 1) * sizeof *where);
    if (!where)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "repose motion: no memory for %d ids",
                         (int)id_max + 1);
    for (int32_t id = 0; id <= id_max; id++)
        where[id] = SIZE_MAX;
    for (size_t i = 0; i < a->n; i++)
        if (cdem_surface_is_free(a, i))
            where[a->id[i]] = i;
    double sum = 0.0;
    for (size_t i = 0; i < b->n; i++) {
        if (!cdem_surface_is_free(b, i) || where[b->id[i]] == SIZE_MAX)
            continue;
        size_t j = where[b->id[i]];
        double d = hypot(b->x[i] - a->x[j], b->y[i] - a->y[j]);
        sum += d;
        m->max = fmax(m->max, d);
        m->n_matched++;
    }
    free(where);
    m->mean = m->n_matched ? sum / (double)m->n_matched : 0.0;
    return CDEM_OK;
}

void cdem_repose_settled(const double *angles, size_t n, const cdem_repose_motion *last,
                         double r_max, cdem_repose_settling *out) {
    memset(out, 0, sizeof *out);
    out->angle_min = INFINITY;
    out->angle_max = -INFINITY;
    int gap = 0;
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(angles[k])) {
            gap = 1;
            continue;
        }
        out->angle_min = fmin(out->angle_min, angles[k]);
        out->angle_max = fmax(out->angle_max, angles[k]);
    }
    out->n = n;
    out->stable = n >= 2 && !gap && out->angle_max - out->angle_min <= CDEM_REPOSE_STABLE_DEG;
    out->at_rest = last && r_max > 0 && last->mean < CDEM_REPOSE_REST_FRACTION * r_max &&
                   last->n_matched == last->n_before; /* and none left the model */
}

cdem_status cdem_repose_spread_of(const double *angles, size_t n, cdem_repose_spread *out,
                                  cdem_error *err) {
    memset(out, 0, sizeof *out);
    out->mean_deg = out->min_deg = out->max_deg = out->sd_deg = out->se_deg = NAN;
    double *x = malloc((n ? n : 1) * sizeof *x);
    if (!x)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "repose: no memory for %zu angles", n);
    for (size_t k = 0; k < n; k++)
        if (isfinite(angles[k]))
            x[out->n++] = angles[k];
    if (out->n) {
        out->mean_deg = gsl_stats_mean(x, 1, out->n);
        gsl_stats_minmax(&out->min_deg, &out->max_deg, x, 1, out->n);
    }
    if (out->n >= 2) {
        out->sd_deg = gsl_stats_sd_m(x, 1, out->n, out->mean_deg); /* divides by n - 1 */
        out->se_deg = out->sd_deg / sqrt((double)out->n);
    }
    free(x);
    return CDEM_OK;
}
