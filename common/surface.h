/* surface: the free surface of an element state, the one definition used by the solver
 * (the overburden load, the top of the assembly, the sea level of the sedimentation) and
 * by the analysis (repose, wedge, voids).
 *
 * The surface is sampled in vertical columns of a column grid (common/grid.h, ny = 1):
 * column c covers x0 + c w <= x < x0 + (c + 1) w, and an element belongs to the column that
 * holds its centre (elements left or right of the grid belong to none). Only free elements
 * count: not a wall, platen or other boundary element, finite position, radius > 0
 * (cdem_surface_is_free). A column's surface element is its free element that reaches
 * highest; among equals the lowest index.
 *
 * "Reaches highest" is measured in one of two ways, and that is the one difference left
 * between the solver and the analysis: the analysis (and the top profile of the assembly)
 * measures the top of an element, y + radius, the surface one sees and measures; the
 * overburden of the solver acts on the element with the highest centre, y, as it always
 * has (choosing by top would move the load onto other elements in columns of mixed radii
 * and change every overburden run, so that is a physics change for its own issue, not part
 * of the issue-20 refactor). The callers choose the origin, width and count of the columns.
 * Ownership: the caller owns the state and the output array. Thread safety: pure
 * functions, no allocation. Units: m. */
#ifndef CDEM_SURFACE_H
#define CDEM_SURFACE_H

#include "grid.h"
#include "state.h"

#include <stddef.h>

/* How a column's surface element is chosen (see the note above). */
typedef enum {
    CDEM_SURFACE_BY_TOP,    /* the highest top, y + radius (analysis, assembly profile) */
    CDEM_SURFACE_BY_CENTRE, /* the highest centre, y (the solver's overburden) */
} cdem_surface_height;

/* 1 when element i of s is a free element with finite position and radius > 0. */
int cdem_surface_is_free(const cdem_state *s, size_t i);

/* top[c] (c < cols->nx) = index of column c's surface element, chosen by `by`, SIZE_MAX for
 * an empty column. cols is a row of columns (cols->ny is not used). Only elements with
 * x_lo <= x < x_hi (centres) are considered (pass -INFINITY/INFINITY for all). */
void cdem_surface_columns(const cdem_state *s, const cdem_grid *cols, cdem_surface_height by,
                          double x_lo, double x_hi, size_t *top);

/* cdem_surface_columns by top over ncol columns of width w (> 0) from x0. */
void cdem_surface_column_tops(const cdem_state *s, double x0, double w, size_t ncol, double x_lo,
                              double x_hi, size_t *top);

/* The highest top (y + radius) of the free elements: the height of the surface; -INFINITY
 * when there are none. */
double cdem_surface_top(const cdem_state *s);

#endif
