/* grid: the one uniform cell grid of the project. Every place that bins elements into
 * cells uses it: the packing of the assembly (solver/packing/assembly.c), the neighbour search and
 * the re-sort of the state (solver/step/neighbour.c), the deposit columns of the sedimentation
 * (solver/packing/sediment.c), the surface columns (common/surface.c: the overburden load and the
 * analysis measurements) and the fixed-radius queries of the analysis (strain fit, axes,
 * cdem2D id matching: cdem_grid_index below).
 *
 * Geometry. Cell (ix, iy) covers x0 + ix cell <= x < x0 + (ix + 1) cell and likewise in y;
 * its index is iy nx + ix (row-major, bottom row first). The column of x is
 * floor((x - x0) / cell), a division (never a multiplication by a stored reciprocal, which
 * can round a point on a cell edge into the other cell), so all users put a point in the
 * same cell. A row of columns (the surface and sediment columns) is a grid with ny = 1.
 * Two ways to treat points off the grid: cdem_grid_col/row/cell clamp them into the edge
 * cells (NaN to cell 0), cdem_grid_col_inside reports them as outside.
 *
 * Counting sort (cdem_grid_sort). Stable: the indices of one cell are listed in ascending
 * order. Together with a fixed scan of a neighbourhood (rows bottom to top, columns left to
 * right, cdem_grid_around / cdem_grid_col_range) this fixes the order in which neighbours
 * are met, hence the pair-list order and every floating-point sum built from it, whatever
 * the thread count.
 *
 * Ownership: cdem_grid is a plain value; the caller owns the key, start and item arrays of
 * cdem_grid_sort. cdem_grid_index owns its arrays (cdem_grid_index_free releases them).
 * Thread safety: no global state; queries on a built index are read-only and may run
 * concurrently. Units: those of the coordinates (m). */
#ifndef CDEM_GRID_H
#define CDEM_GRID_H

#include "cdem_error.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>

typedef struct {
    double x0, y0; /* lower-left corner of cell (0, 0) */
    double cell;   /* cell side, > 0 (+inf after cdem_grid_fit gave up: one cell) */
    size_t nx, ny; /* cells along x and y, >= 1 */
} cdem_grid;

/* The cells around a point or a cell: columns x_lo..x_hi and rows y_lo..y_hi, inclusive. */
typedef struct {
    size_t x_lo, x_hi, y_lo, y_hi;
} cdem_grid_box;

/* floor((v - origin) / cell): the unclamped cell coordinate as a double (negative, beyond
 * the grid or NaN for such inputs). */
static inline double cdem_grid_coord(double v, double origin, double cell) {
    return floor((v - origin) / cell);
}

/* A cell coordinate clamped to 0..n-1 (NaN gives 0). */
static inline size_t cdem_grid_clamp(double f, size_t n) {
    if (!(f >= 0.0))
        return 0;
    return f < (double)n ? (size_t)f : n - 1;
}

/* The column of x / the row of y, clamped into the grid. */
static inline size_t cdem_grid_col(const cdem_grid *g, double x) {
    return cdem_grid_clamp(cdem_grid_coord(x, g->x0, g->cell), g->nx);
}
static inline size_t cdem_grid_row(const cdem_grid *g, double y) {
    return cdem_grid_clamp(cdem_grid_coord(y, g->y0, g->cell), g->ny);
}

/* The cell index (row-major) of the point (x, y), clamped into the grid. */
static inline size_t cdem_grid_cell(const cdem_grid *g, double x, double y) {
    return cdem_grid_row(g, y) * g->nx + cdem_grid_col(g, x);
}

/* 1 with *col set when x falls in a column of the grid (0 <= column < nx); 0 when it is
 * left or right of the grid or NaN. */
static inline int cdem_grid_col_inside(const cdem_grid *g, double x, size_t *col) {
    const double f = cdem_grid_coord(x, g->x0, g->cell);
    if (!(f >= 0.0 && f < (double)g->nx))
        return 0;
    *col = (size_t)f;
    return 1;
}

/* Inclusive columns a..b of the cells that meet [lo, hi], clipped to the grid. 0 when the
 * interval misses the grid (or is NaN). */
int cdem_grid_col_range(const cdem_grid *g, double lo, double hi, size_t *a, size_t *b);
/* The same for rows and [lo, hi] in y. */
int cdem_grid_row_range(const cdem_grid *g, double lo, double hi, size_t *a, size_t *b);

/* The cells within one cell of cell c (the 3 x 3 block, clipped to the grid): every point
 * closer than one cell side to a point of c lies in them. */
static inline cdem_grid_box cdem_grid_around(const cdem_grid *g, size_t c) {
    const size_t cx = c % g->nx, cy = c / g->nx;
    return (cdem_grid_box){.x_lo = cx > 0 ? cx - 1 : 0,
                           .x_hi = cx + 1 < g->nx ? cx + 1 : cx,
                           .y_lo = cy > 0 ? cy - 1 : 0,
                           .y_hi = cy + 1 < g->ny ? cy + 1 : cy};
}

/* Fits a grid to the box [xmin, xmax] x [ymin, ymax] (xmin <= xmax, ymin <= ymax, finite):
 * origin (xmin, ymin), cells of side `cell` (> 0), nx = floor((xmax - xmin) / cell) + 1,
 * ny likewise. While that makes more than max_cells cells the side is doubled (a stray
 * far-away point must not make the grid huge: memory stays O(max_cells)). Returns 1; 0
 * when the side overflowed to infinity before the grid fitted (the grid is then one cell
 * of infinite side). */
int cdem_grid_fit(cdem_grid *g, double xmin, double xmax, double ymin, double ymax, double cell,
                  double max_cells);

/* Stable counting sort of the indices 0..n-1 by key[i] in 0..nkeys-1; an index with a
 * negative key is left out. Afterwards items[start[k]] .. items[start[k + 1] - 1] are the
 * indices of key k in ascending order; start holds nkeys + 1 entries, items as many as
 * there are indices with a key. n must be <= INT32_MAX. Returns the number of indices
 * sorted (start[nkeys]). */
size_t cdem_grid_sort(const int32_t *key, size_t n, size_t nkeys, int32_t *start, int32_t *items);

/* A point index: a grid fitted to the bounding box of a point set and the points sorted
 * into its cells, for fixed-radius neighbour queries (the analysis). */
typedef struct {
    cdem_grid grid; /* fitted to the included points; one cell at (0, 0) when there are none */
    int32_t *start; /* nx ny + 1 offsets: cell c holds items[start[c] .. start[c + 1] - 1] */
    int32_t *items; /* point indices grouped by cell, ascending within a cell */
} cdem_grid_index;

/* Builds the index of the n points (x[i], y[i]) with include[i] != 0 (include may be NULL:
 * all) and finite coordinates, with cells of side >= cell (> 0, finite; so that a query of
 * radius <= cell visits at most 3 x 3 cells). The side is doubled while the grid would
 * have more than 4 (points) + 64 cells. n must be <= (INT32_MAX - 64) / 4. */
cdem_status cdem_grid_index_build(cdem_grid_index *ix, const double *x, const double *y, size_t n,
                                  const unsigned char *include, double cell, cdem_error *err);

/* The cells meeting the square [px - r, px + r] x [py - r, py + r], clipped to the grid.
 * Returns 0 when the square misses the grid (or px, py are not finite, r < 0, or the
 * index is not built). */
int cdem_grid_index_range(const cdem_grid_index *ix, double px, double py, double r,
                          cdem_grid_box *box);

/* Releases the arrays (accepts NULL and a zeroed index). */
void cdem_grid_index_free(cdem_grid_index *ix);

#endif
