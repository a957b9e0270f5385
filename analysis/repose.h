/* repose: the angle of repose of a pile's final free surface.
 *
 * The free surface is sampled in vertical columns of width 2 x the largest free-element
 * radius, from the leftmost to the rightmost free element: each column's surface element
 * is its highest non-wall element (by top, y + radius; an element belongs to the column
 * holding its centre). Only the slope is fitted: columns whose top lies strictly between
 * lo + 10 % and lo + 90 % of the height drop (lo, hi = lowest and highest column tops) are
 * kept, which excludes the flat crest and the flat toe. A least-squares line
 * top = intercept + slope x goes through the kept tops; the angle is atan(|slope|).
 * Ownership: the caller owns the state. Thread safety: pure function; scratch memory is
 * allocated per call. Units: m; angle in degrees. */
#ifndef CDEM_REPOSE_H
#define CDEM_REPOSE_H

#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

typedef struct {
    double angle_deg;        /* angle of repose, degrees, 0..90 */
    double slope, intercept; /* fitted line top = intercept + slope x (slope dimensionless) */
    double x_first, x_last;  /* m, x range of the fitted surface elements */
    double column_width;     /* m, 2 x largest free radius */
    size_t n_columns;        /* columns holding a free element */
    size_t n_fitted;         /* surface elements in the fit, >= 2 */
    double residual_rms;     /* m, rms distance of the fitted tops from the line (vertical) */
} cdem_repose_result;

/* Measures the angle of repose of state s. Fails when s has no free elements, or fewer
 * than 2 surface columns on the slope (a flat or one-column surface). */
cdem_status cdem_repose_measure(const cdem_state *s, cdem_repose_result *res, cdem_error *err);

#endif
