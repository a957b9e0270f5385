/* colorlimits: see colorlimits.h. Sorting a copy (qsort) is O(n log n) per call; the analysis
 * context caches the limits that span many increments (stress over all increments). */
#include "colorlimits.h"

#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdlib.h>

double cdem_limits_quantile_sorted(const double *sorted, size_t n, double f) {
    return gsl_stats_quantile_from_sorted_data(sorted, 1, n, f);
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void set_threshold(cdem_limits *l) {
    l->threshold = CDEM_LIMITS_ONLY_ABOVE * fmax(fabs(l->vmin), fabs(l->vmax));
}

cdem_limits cdem_limits_fixed(double vmin, double vmax) {
    cdem_limits l = {vmin, vmax, 0.0, 0};
    set_threshold(&l);
    return l;
}

cdem_status cdem_limits_from_values(const double *values, size_t n, double lo, double hi,
                                    int symmetric, double cap, cdem_limits *out, cdem_error *err) {
    if (!(lo >= 0.0 && lo <= hi && hi <= 1.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "colour limits: quantiles %g and %g must satisfy 0 <= lo <= hi <= 1", lo,
                         hi);
    double *v = malloc((n ? n : 1) * sizeof *v);
    if (!v)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "colour limits: out of memory for %zu values", n);
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (isfinite(values[i]))
            v[m++] = values[i];
    *out = cdem_limits_fixed(0.0, 0.0);
    if (m > 0) {
        qsort(v, m, sizeof *v, cmp_double);
        double a = cdem_limits_quantile_sorted(v, m, lo), b = cdem_limits_quantile_sorted(v, m, hi);
        if (symmetric) {
            double mag = fmax(fabs(a), fabs(b));
            a = -mag;
            b = mag;
        }
        if (cap > 0.0) {
            a = fmin(fmax(a, -cap), cap);
            b = fmin(fmax(b, -cap), cap);
        }
        *out = cdem_limits_fixed(a, b);
        out->count = m;
    }
    free(v);
    return CDEM_OK;
}

int cdem_limits_above(const cdem_limits *lim, double value) {
    return isfinite(value) && fabs(value) > lim->threshold;
}
