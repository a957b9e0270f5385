/* surface: the free surface of an element state, sampled in vertical columns.
 *
 * Column c covers x0 + c w <= x < x0 + (c + 1) w; an element belongs to the column that
 * holds its centre. A column's surface element is its free (non-wall, finite, r > 0)
 * element with the highest top (y + radius). Used by the repose and wedge measurements
 * (analysis/measure/repose.c, analysis/measure/wedge.c), which choose x0, w and the column count.
 * Ownership: the caller owns the state and the output array. Thread safety: pure
 * functions, no allocation. Units: m. */
#ifndef CDEM_SURFACE_H
#define CDEM_SURFACE_H

#include "state.h"

#include <stddef.h>

/* 1 when element i of s is a free element with finite position and radius > 0. */
int cdem_surface_is_free(const cdem_state *s, size_t i);

/* top[c] (c < ncol) = index of column c's surface element, SIZE_MAX for an empty column.
 * Only elements with x_lo <= x < x_hi (centres) are considered (pass -INFINITY/INFINITY
 * for all); elements outside the ncol columns are ignored. w must be > 0. */
void cdem_surface_column_tops(const cdem_state *s, double x0, double w, size_t ncol, double x_lo,
                              double x_hi, size_t *top);

#endif
