/* colorlimits (module "limits"; not named limits.h so it never shadows <limits.h>): colour-bar
 * limits (as the original program chooses them; docs/analysis.md) and the percentile they are built
 * from.
 *
 * Percentile definition (the one of gsl_stats_quantile_from_sorted_data, used directly): for
 * n finite values sorted ascending, the f-quantile is v[i] + (v[i+1] - v[i]) (h - i) with
 * h = (n - 1) f, i = floor(h). NaN/Inf values are ignored. Displacement and stress limits are
 * the 1st and 99th percentiles; signed quantities get [-m, m] with m the larger magnitude;
 * stress is clipped to +-CDEM_LIMITS_STRESS_CAP. Strain limits are fixed (see analysis.h).
 * The "only above" mode colours only elements whose |value| > 0.1 x max(|vmin|, |vmax|).
 * Ownership: plain values. Thread safety: pure. Units: those of the quantity. */
#ifndef CDEM_COLORLIMITS_H
#define CDEM_COLORLIMITS_H

#include "cdem_error.h"

#include <stddef.h>

#define CDEM_LIMITS_STRESS_CAP 200e6 /* N/m: largest stress magnitude on a colour bar */
#define CDEM_LIMITS_ONLY_ABOVE 0.1   /* fraction of the maximum for the "only above" mode */

typedef struct {
    double vmin;      /* value at the low end of the colour bar */
    double vmax;      /* value at the high end, >= vmin (equal when there is no data) */
    double threshold; /* only-above mode: colour only |value| > threshold, >= 0 */
    size_t count;     /* finite values the limits were computed from (0 for fixed limits) */
} cdem_limits;

/* f-quantile (0 <= f <= 1) of n sorted finite values (n >= 1), gsl definition. */
double cdem_limits_quantile_sorted(const double *sorted, size_t n, double f);

/* Limits from the lo and hi quantiles of the finite values among values[0..n); symmetric
 * around zero when symmetric; clipped to [-cap, cap] when cap > 0. No finite value gives
 * vmin = vmax = 0 and count 0. */
cdem_status cdem_limits_from_values(const double *values, size_t n, double lo, double hi,
                                    int symmetric, double cap, cdem_limits *out, cdem_error *err);

/* Fixed limits [vmin, vmax] (the threshold follows). */
cdem_limits cdem_limits_fixed(double vmin, double vmax);

/* 1 when value is coloured in the only-above mode. */
int cdem_limits_above(const cdem_limits *lim, double value);

#endif
