/* cellgrid: see cellgrid.h. A counting sort (two passes over the points) instead of linked
 * lists keeps each cell's items contiguous, which is what the strain fit streams through. */
#include "cellgrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int usable(const double *x, const double *y, const unsigned char *include, size_t i) {
    return (!include || include[i]) && isfinite(x[i]) && isfinite(y[i]);
}

cdem_status cdem_cellgrid_build(cdem_cellgrid *g, const double *x, const double *y, size_t n,
                                const unsigned char *include, double cell, cdem_error *err) {
    memset(g, 0, sizeof *g);
    if (!(cell > 0.0) || !isfinite(cell))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cell grid: cell size %g must be finite and > 0",
                         cell);
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
    /* Enlarge the cell until the grid has at most 4 * used + 64 cells. */
    double max_cells = 4.0 * (double)used + 64.0;
    for (;;) {
        double cx = floor((xmax - xmin) / cell) + 1.0, cy = floor((ymax - ymin) / cell) + 1.0;
        if (isfinite(cx) && isfinite(cy) && cx * cy <= max_cells)
            break;
        cell *= 2.0;
        if (!isfinite(cell))
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "cell grid: point extent %g x %g is too large to grid", xmax - xmin,
                             ymax - ymin);
    }
    g->x0 = xmin;
    g->y0 = ymin;
    g->cell = cell;
    g->nx = (size_t)floor((xmax - xmin) / cell) + 1;
    g->ny = (size_t)floor((ymax - ymin) / cell) + 1;
    size_t ncell = g->nx * g->ny;
    g->start = calloc(ncell + 1, sizeof *g->start);
    g->items = malloc((used ? used : 1) * sizeof *g->items);
    if (!g->start || !g->items) {
        cdem_cellgrid_free(g);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "cell grid: out of memory for %zu cells", ncell);
    }
    for (size_t i = 0; i < n; i++) {
        if (!usable(x, y, include, i))
            continue;
        size_t ix = (size_t)((x[i] - xmin) / cell), iy = (size_t)((y[i] - ymin) / cell);
        if (ix >= g->nx)
            ix = g->nx - 1;
        if (iy >= g->ny)
            iy = g->ny - 1;
        g->start[iy * g->nx + ix + 1]++;
    }
    for (size_t c = 0; c < ncell; c++)
        g->start[c + 1] += g->start[c];
    size_t *fill = malloc(ncell * sizeof *fill);
    if (!fill) {
        cdem_cellgrid_free(g);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "cell grid: out of memory for %zu cells", ncell);
    }
    memcpy(fill, g->start, ncell * sizeof *fill);
    for (size_t i = 0; i < n; i++) {
        if (!usable(x, y, include, i))
            continue;
        size_t ix = (size_t)((x[i] - xmin) / cell), iy = (size_t)((y[i] - ymin) / cell);
        if (ix >= g->nx)
            ix = g->nx - 1;
        if (iy >= g->ny)
            iy = g->ny - 1;
        g->items[fill[iy * g->nx + ix]++] = i;
    }
    free(fill);
    return CDEM_OK;
}

static int clip_range(double lo, double hi, double origin, double cell, size_t ncell, size_t *a,
                      size_t *b) {
    double flo = floor((lo - origin) / cell), fhi = floor((hi - origin) / cell);
    if (!(fhi >= 0.0) || !(flo <= (double)(ncell - 1)))
        return 0;
    *a = flo < 0.0 ? 0 : (size_t)flo;
    *b = fhi > (double)(ncell - 1) ? ncell - 1 : (size_t)fhi;
    return 1;
}

int cdem_cellgrid_range(const cdem_cellgrid *g, double px, double py, double r, size_t *ix0,
                        size_t *ix1, size_t *iy0, size_t *iy1) {
    if (!g->start || !isfinite(px) || !isfinite(py) || !(r >= 0.0))
        return 0;
    return clip_range(px - r, px + r, g->x0, g->cell, g->nx, ix0, ix1) &&
           clip_range(py - r, py + r, g->y0, g->cell, g->ny, iy0, iy1);
}

void cdem_cellgrid_free(cdem_cellgrid *g) {
    if (!g)
        return;
    free(g->start);
    free(g->items);
    memset(g, 0, sizeof *g);
}
