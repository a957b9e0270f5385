/* grid: see grid.h. The counting sort keeps each cell's items contiguous (better than
 * linked lists for the streaming scans of the neighbour search and the strain fit); it
 * runs the start array as the fill cursor and shifts it back afterwards, so it needs no
 * scratch beyond its output. */
#include "grid.h"

#include <stdlib.h>
#include <string.h>

/* Inclusive coordinates of the cells meeting [lo, hi] along one axis of n cells. */
static int clip_range(double lo, double hi, double origin, double cell, size_t n, size_t *a,
                      size_t *b) {
    const double flo = cdem_grid_coord(lo, origin, cell), fhi = cdem_grid_coord(hi, origin, cell);
    if (!(fhi >= 0.0) || !(flo <= (double)(n - 1)))
        return 0;
    *a = flo < 0.0 ? 0 : (size_t)flo;
    *b = fhi > (double)(n - 1) ? n - 1 : (size_t)fhi;
    return 1;
}

int cdem_grid_col_range(const cdem_grid *g, double lo, double hi, size_t *a, size_t *b) {
    return clip_range(lo, hi, g->x0, g->cell, g->nx, a, b);
}

int cdem_grid_row_range(const cdem_grid *g, double lo, double hi, size_t *a, size_t *b) {
    return clip_range(lo, hi, g->y0, g->cell, g->ny, a, b);
}

int cdem_grid_fit(cdem_grid *g, double xmin, double xmax, double ymin, double ymax, double cell,
                  double max_cells) {
    g->x0 = xmin;
    g->y0 = ymin;
    for (;;) {
        const double cx = floor((xmax - xmin) / cell) + 1.0, cy = floor((ymax - ymin) / cell) + 1.0;
        if (isfinite(cx) && isfinite(cy) && cx * cy <= max_cells) {
            g->cell = cell;
            g->nx = (size_t)cx;
            g->ny = (size_t)cy;
            return 1;
        }
        cell *= 2.0;
        if (!isfinite(cell)) {
            g->cell = cell;
            g->nx = g->ny = 1;
            return 0;
        }
    }
}

size_t cdem_grid_sort(const int32_t *key, size_t n, size_t nkeys, int32_t *start, int32_t *items) {
    memset(start, 0, (nkeys + 1) * sizeof *start);
    for (size_t i = 0; i < n; i++)
        if (key[i] >= 0)
            start[key[i] + 1]++;
    for (size_t k = 0; k < nkeys; k++)
        start[k + 1] += start[k];
    /* start[k] serves as the fill cursor of key k, shifted back below */
    for (size_t i = 0; i < n; i++)
        if (key[i] >= 0)
            items[start[key[i]]++] = (int32_t)i;
    for (size_t k = nkeys; k > 0; k--)
        start[k] = start[k - 1];
    start[0] = 0;
    return (size_t)start[nkeys];
}

static int usable(const double *x, const double *y, const unsigned char *include, size_t i) {
    return (!include || include[i]) && isfinite(x[i]) && isfinite(y[i]);
}

cdem_status cdem_grid_index_build(cdem_grid_index *ix, const double *x, const double *y, size_t n,
                                  const unsigned char *include, double cell, cdem_error *err) {
    memset(ix, 0, sizeof *ix);
    if (!(cell > 0.0) || !isfinite(cell))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cell grid: cell size %g must be finite and > 0",
                         cell);
    /* cell indices (up to 4 n + 64) and item indices are int32 */
    if (n > (INT32_MAX - 64) / 4)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "cell grid: %zu points: at most %d", n,
                         (int)((INT32_MAX - 64) / 4));
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    size_t used = 0;
    for (size_t i = 0; i < n; i++) {
        if (!usable(x, y, include, i))
            continue;
        used++;
        xmin = fmin(xmin, x[i]);
        xmax = fmax(xmax, x[i]);
        ymin = fmin(ymin, y[i]);
        ymax = fmax(ymax, y[i]);
    }
    if (used == 0) {
        xmin = xmax = ymin = ymax = 0.0;
    }
    if (!cdem_grid_fit(&ix->grid, xmin, xmax, ymin, ymax, cell, 4.0 * (double)used + 64.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cell grid: point extent %g x %g is too large to grid", xmax - xmin,
                         ymax - ymin);
    const size_t ncell = ix->grid.nx * ix->grid.ny;
    ix->start = malloc((ncell + 1) * sizeof *ix->start);
    ix->items = malloc((used ? used : 1) * sizeof *ix->items);
    int32_t *key = malloc((n ? n : 1) * sizeof *key);
    if (!ix->start || !ix->items || !key) {
        free(key);
        cdem_grid_index_free(ix);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "cell grid: out of memory for %zu cells", ncell);
    }
    for (size_t i = 0; i < n; i++)
        key[i] = usable(x, y, include, i) ? (int32_t)cdem_grid_cell(&ix->grid, x[i], y[i]) : -1;
    cdem_grid_sort(key, n, ncell, ix->start, ix->items);
    free(key);
    return CDEM_OK;
}

int cdem_grid_index_range(const cdem_grid_index *ix, double px, double py, double r,
                          cdem_grid_box *box) {
    if (!ix->start || !isfinite(px) || !isfinite(py) || !(r >= 0.0))
        return 0;
    return cdem_grid_col_range(&ix->grid, px - r, px + r, &box->x_lo, &box->x_hi) &&
           cdem_grid_row_range(&ix->grid, py - r, py + r, &box->y_lo, &box->y_hi);
}

void cdem_grid_index_free(cdem_grid_index *ix) {
    if (!ix)
        return;
    free(ix->start);
    free(ix->items);
    memset(ix, 0, sizeof *ix);
}
