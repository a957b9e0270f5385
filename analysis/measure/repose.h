/* repose: the angle of repose of a pile's final free surface.
 *
 * The free surface is sampled in vertical columns of width 2 x the largest free-element
 * radius, from the leftmost to the rightmost free element: each column's surface element
 * is its highest non-wall element (by top, y + radius; an element belongs to the column
 * holding its centre). Only the slope is fitted: columns whose top lies strictly between
 * lo + 10 % and lo + 90 % of the height drop (lo, hi = lowest and highest column tops) are
 * kept, which excludes the flat crest and the flat toe. The kept columns are split at
 * the crest (the highest column) into a left and a right flank; a flank is fitted when it
 * holds at least 2 columns and 25 % of the kept ones (so a pile collapsed to one side has
 * one flank, a mound two). A least-squares line top = intercept + slope x goes through
 * each fitted flank's tops; its angle is atan(|slope|); the result is the mean over the
 * fitted flanks weighted by their column counts.
 * Ownership: the caller owns the state. Thread safety: pure function; scratch memory is
 * allocated per call. Units: m; angle in degrees. */
#ifndef CDEM_REPOSE_H
#define CDEM_REPOSE_H

#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

/* One fitted flank of the surface. */
typedef struct {
    double angle_deg;        /* atan(|slope|), degrees, 0..90 */
    double slope, intercept; /* fitted line top = intercept + slope x (slope dimensionless) */
    double x_first, x_last;  /* m, x range of the fitted surface elements */
    size_t n;                /* surface elements in the fit, >= 2 (0: flank not fitted) */
    double residual_rms;     /* m, rms vertical distance of the fitted tops from the line */
} cdem_repose_flank;

typedef struct {
    double angle_deg;           /* angle of repose, degrees, 0..90 (weighted flank mean) */
    cdem_repose_flank flank[2]; /* 0: left of the crest, 1: right; n = 0 when not fitted */
    double column_width;        /* m, 2 x largest free radius */
    size_t n_columns;           /* columns holding a free element */
    size_t n_fitted;            /* surface elements in the fits (both flanks), >= 2 */
    double crest_x;             /* m, x of the highest surface element */
} cdem_repose_result;

/* Measures the angle of repose of state s. Fails when s has no free elements, or fewer
 * than 2 surface columns on the slope (a flat or one-column surface). */
cdem_status cdem_repose_measure(const cdem_state *s, cdem_repose_result *res, cdem_error *err);

#endif
