/* cellgrid: a uniform cell grid over 2-D points for fixed-radius neighbour queries.
 *
 * Points are bucketed by a counting sort into square cells of side `cell` (>= the query
 * radius, so a query visits at most 3 x 3 cells). Items inside a cell keep ascending point
 * order, so every query visits neighbours in one fixed order whatever the thread count.
 * Points with a zero include flag or a non-finite coordinate are left out. When the
 * bounding box would need more than 4n + 64 cells (bad input, a far-away element) the cell
 * is enlarged so memory stays O(n).
 * Ownership: the grid owns its arrays; cdem_cellgrid_free releases them (accepts NULL).
 * Thread safety: build is single-threaded; queries on a built grid are read-only and may run
 * concurrently. Units: whatever the coordinates use (m). */
#ifndef CDEM_CELLGRID_H
#define CDEM_CELLGRID_H

#include "cdem_error.h"

#include <stddef.h>

typedef struct {
    double x0, y0; /* lower-left corner of cell (0,0), same unit as the points */
    double cell;   /* cell side, > 0 */
    size_t nx, ny; /* cells along x and y, >= 1 */
    size_t *start; /* nx*ny + 1 offsets into items; cell c holds items[start[c]..start[c+1]) */
    size_t *items; /* point indices, grouped by cell, ascending within a cell */
} cdem_cellgrid;

/* Builds the grid over the n points (x[i], y[i]) with include[i] != 0 (include may be NULL:
 * all points). cell must be > 0 and finite. */
cdem_status cdem_cellgrid_build(cdem_cellgrid *g, const double *x, const double *y, size_t n,
                                const unsigned char *include, double cell, cdem_error *err);

/* Inclusive cell ranges covering the square [px - r, px + r] x [py - r, py + r], clipped to
 * the grid. Returns 0 when the square misses the grid entirely (or px, py are not finite). */
int cdem_cellgrid_range(const cdem_cellgrid *g, double px, double py, double r, size_t *ix0,
                        size_t *ix1, size_t *iy0, size_t *iy1);

void cdem_cellgrid_free(cdem_cellgrid *g);

#endif
