/* repose: see repose.h. */
#include "repose.h"
#include "surface.h"

#include <gsl/gsl_fit.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

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
        f->angle_deg = atan(fabs(c1)) * 180.0 / 3.14159265358979323846;
        f->x_first = fx[k0];
        f->x_last = fx[k0 + k - 1];
        f->n = k;
        f->residual_rms = sqrt(ss / k);
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
