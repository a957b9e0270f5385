/* voids: see voids.h. */
#include "voids.h"

#include "surface.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Raster cells at most (the cell grows beyond a quarter radius for huge models). */
#define VOIDS_MAX_CELLS 40000000.0

/* Sample cells of the surface at most (the cell grows beyond r_max / 8 for huge models). */
#define VOIDS_MAX_SURFACE_CELLS 10000000.0

/* The steepest slope (voids.h). The surface is sampled in narrow cells of width h, about
 * r_max / 8, h dividing `window` (common/surface.h: each cell's highest top). Its envelope
 * at cell k is the highest top in cells k - m .. k + m (a column of about 2 r_max centred
 * there, slid along the model rather than fixed in place), and its height at k the mean of
 * the envelope over those cells. The mean smooths the envelope's steps where a single high
 * element enters or leaves the column; without it, the steepest reading picked the one
 * placement of many where a high element and a notch a kilometre apart lined up (5 degrees
 * on Fig. 11B's flat growth surface, 3 with it). Only columns wholly inside the free
 * elements' extent [xmin, xmax] count. The slope is taken between heights exactly `window`
 * apart. So the reading depends neither on where fixed columns would fall nor on a column
 * cut short by the extent's end. (Fixed columns of exactly 2 r_max from xmin, the slope
 * taken between their highest tops to the first column at least `window` away, read 59
 * degrees at Fig. 12B's moving wall, where the last column, 29 m wide, held only five
 * small elements against the wall's face, the highest 3 km below the surface, and moved by
 * up to 3 degrees with the columns' places elsewhere.) Returns -1 when out of memory. */
static int steepest_slope(const cdem_state *s, double xmin, double xmax, double rmax,
                          cdem_voids_result *res) {
    const double window = res->window, span = xmax - xmin;
    if (!(span > window))
        return 0; /* no two heights a window apart (and no huge cell counts below) */
    double per = ceil(window / (rmax / 8.0)); /* cells per window (window >= 2 rmax: >= 16) */
    if (span / (window / per) > VOIDS_MAX_SURFACE_CELLS)
        per = fmax(1.0, floor(VOIDS_MAX_SURFACE_CELLS * window / span));
    const double h = window / per;
    const long q = (long)per, m = (long)floor(rmax / h), nc = (long)floor(span / h) + 1;
    res->column_width = (double)(2 * m + 1) * h;
    size_t *top = malloc((size_t)nc * sizeof *top);
    double *envelope = malloc((size_t)nc * sizeof *envelope);
    double *height = malloc((size_t)nc * sizeof *height);
    if (!top || !envelope || !height) {
        free(top);
        free(envelope);
        free(height);
        return -1;
    }
    cdem_surface_column_tops(s, xmin, h, (size_t)nc, -INFINITY, INFINITY, top);
    /* -INFINITY: a column reaching beyond the extent, or empty */
    for (long k = 0; k < nc; k++) {
        envelope[k] = -INFINITY;
        if (k < m || k + m >= nc)
            continue;
        for (long c = k - m; c <= k + m; c++)
            if (top[c] != SIZE_MAX)
                envelope[k] = fmax(envelope[k], s->y[top[c]] + s->radius[top[c]]);
    }
    for (long k = 0; k < nc; k++) {
        double sum = 0.0;
        for (long c = k - m; c <= k + m && isfinite(sum); c++)
            sum = c < 0 || c >= nc ? -INFINITY : sum + envelope[c];
        height[k] = sum / (double)(2 * m + 1);
    }
    for (long k = 0; k + q < nc; k++) {
        const double ya = height[k], yb = height[k + q];
        if (!isfinite(ya) || !isfinite(yb))
            continue;
        const double deg = atan(fabs(yb - ya) / window) * 180.0 / M_PI;
        if (deg > res->steepest_deg) {
            res->steepest_deg = deg;
            res->steepest_x0 = xmin + ((double)k + 0.5) * h;
            res->steepest_x1 = res->steepest_x0 + window;
        }
    }
    free(top);
    free(envelope);
    free(height);
    return 0;
}

/* Marks the cells whose centre lies inside disc (x, y, r) with value v. */
static void paint(uint8_t *g, long nx, long ny, double gx0, double gy0, double h, double x,
                  double y, double r, uint8_t v) {
    long i0 = (long)floor((x - r - gx0) / h), i1 = (long)ceil((x + r - gx0) / h);
    long j0 = (long)floor((y - r - gy0) / h), j1 = (long)ceil((y + r - gy0) / h);
    i0 = i0 < 0 ? 0 : i0;
    j0 = j0 < 0 ? 0 : j0;
    i1 = i1 >= nx ? nx - 1 : i1;
    j1 = j1 >= ny ? ny - 1 : j1;
    for (long j = j0; j <= j1; j++) {
        const double cy = gy0 + (j + 0.5) * h - y;
        for (long i = i0; i <= i1; i++) {
            const double cx = gx0 + (i + 0.5) * h - x;
            if (cx * cx + cy * cy <= r * r && g[j * nx + i] < v)
                g[j * nx + i] = v;
        }
    }
}

enum { CELL_EMPTY = 0, CELL_BOUNDARY = 1, CELL_FREE = 2 };

/* Chamfer distance (in cells) of every cell to the nearest solid cell: two passes with
 * weights 1 (edge) and sqrt(2) (corner); solid cells get 0. near[c] receives the kind of that
 * solid cell (CELL_FREE or CELL_BOUNDARY; CELL_EMPTY where there is none). */
static void relax(float *d, uint8_t *near, long c, long from, float w) {
    if (d[from] + w < d[c]) {
        d[c] = d[from] + w;
        near[c] = near[from];
    }
}

static void clearance(const uint8_t *g, long nx, long ny, float *d, uint8_t *near) {
    const float big = 1e30f, diag = (float)M_SQRT2;
    for (long c = 0; c < nx * ny; c++) {
        d[c] = g[c] == CELL_EMPTY ? big : 0.0f;
        near[c] = g[c];
    }
    for (long j = 0; j < ny; j++)
        for (long i = 0; i < nx; i++) {
            const long c = j * nx + i;
            if (i > 0)
                relax(d, near, c, c - 1, 1.0f);
            if (j > 0) {
                relax(d, near, c, c - nx, 1.0f);
                if (i > 0)
                    relax(d, near, c, c - nx - 1, diag);
                if (i + 1 < nx)
                    relax(d, near, c, c - nx + 1, diag);
            }
        }
    for (long j = ny - 1; j >= 0; j--)
        for (long i = nx - 1; i >= 0; i--) {
            const long c = j * nx + i;
            if (i + 1 < nx)
                relax(d, near, c, c + 1, 1.0f);
            if (j + 1 < ny) {
                relax(d, near, c, c + nx, 1.0f);
                if (i + 1 < nx)
                    relax(d, near, c, c + nx + 1, diag);
                if (i > 0)
                    relax(d, near, c, c + nx - 1, diag);
            }
        }
}

/* The k-th (0..3: left, right, below, above) 4-neighbour of cell c of an nx x ny raster:
 * 1 with its index in *cb, or 0 when it lies outside the raster. */
static int neighbour4(long c, int k, long nx, long ny, long *cb) {
    const long i = c % nx + (k == 1) - (k == 0), j = c / nx + (k == 3) - (k == 2);
    if (i < 0 || i >= nx || j < 0 || j >= ny)
        return 0;
    *cb = j * nx + i;
    return 1;
}

/* Marks with bit `mark` every cell a probe of clearance >= `need` (cells) reaches from the
 * top row through cells of clearance >= need. */
static void reach_from_sky(const float *d, uint8_t *m, uint8_t mark, long nx, long ny, float need,
                           long *stack) {
    long sp = 0;
    for (long i = 0; i < nx; i++) {
        const long c = (ny - 1) * nx + i;
        if (d[c] >= need) {
            m[c] |= mark;
            stack[sp++] = c;
        }
    }
    while (sp > 0) {
        const long c = stack[--sp];
        for (int k = 0; k < 4; k++) {
            long cb;
            if (!neighbour4(c, k, nx, ny, &cb))
                continue;
            if ((m[cb] & mark) || !(d[cb] >= need))
                continue;
            m[cb] |= mark;
            stack[sp++] = cb;
        }
    }
}

/* Flood fill of the 4-connected region of cells with all bits want_set from c0, marking them
 * with bit `mark`; returns the cell count, the lowest and highest row, and in *rock 1 when
 * the region lies in the rock mass (at least as many of its cells have a free element as
 * their nearest solid as a boundary element: a slot between walls or below the base along a
 * fault ramp is not the rock's). */
static long region(uint8_t *m, const uint8_t *near, uint8_t want_set, uint8_t mark, long nx,
                   long ny, long c0, long *stack, long *jlo, long *jhi, int *rock) {
    long n = 0, sp = 0, nfree = 0, nbound = 0;
    *jlo = *jhi = c0 / nx;
    m[c0] |= mark;
    stack[sp++] = c0;
    while (sp > 0) {
        const long c = stack[--sp];
        const long j = c / nx;
        n++;
        nfree += near[c] == CELL_FREE;
        nbound += near[c] == CELL_BOUNDARY;
        *jlo = j < *jlo ? j : *jlo;
        *jhi = j > *jhi ? j : *jhi;
        for (int k = 0; k < 4; k++) {
            long cb;
            if (!neighbour4(c, k, nx, ny, &cb))
                continue;
            if ((m[cb] & mark) || (m[cb] & want_set) != want_set)
                continue;
            m[cb] |= mark;
            stack[sp++] = cb;
        }
    }
    *rock = nfree > 0 && nfree >= nbound;
    return n;
}

/* Open fissures (voids.h): in every raster column, the depth of its first solid cell below
 * the lower of the highest free-element cells within 2 rmax on either side. */
static void fissures(const uint8_t *g, long nx, long ny, double h, double gx0, double gy0,
                     double rmax, cdem_voids_result *res) {
    const long k = (long)ceil(2.0 * rmax / h);
    res->fissure_width = 2.0 * rmax;
    long *top = malloc((size_t)nx * sizeof *top), *first = malloc((size_t)nx * sizeof *first);
    if (!top || !first) {
        free(top);
        free(first);
        return; /* the measure stays 0; the others are complete */
    }
    for (long i = 0; i < nx; i++) {
        top[i] = first[i] = -1;
        for (long j = ny - 1; j >= 0; j--) {
            const uint8_t c = g[j * nx + i];
            if (c != CELL_EMPTY && first[i] < 0)
                first[i] = j;
            if (c == CELL_FREE) {
                top[i] = j;
                break;
            }
        }
    }
    for (long i = k; i + k < nx; i++) {
        long left = -1, right = -1;
        for (long a = i - k; a < i; a++)
            left = top[a] > left ? top[a] : left;
        for (long a = i + 1; a <= i + k; a++)
            right = top[a] > right ? top[a] : right;
        if (left < 0 || right < 0 || first[i] < 0)
            continue;
        const long rim = left < right ? left : right;
        const double depth = (double)(rim - first[i]) * h;
        if (depth > res->fissure_depth) {
            res->fissure_depth = depth;
            res->fissure_x = gx0 + (i + 0.5) * h;
            res->fissure_y = gy0 + (first[i] + 0.5) * h;
        }
    }
    free(top);
    free(first);
}

cdem_status cdem_voids_measure(const cdem_state *s, double window, cdem_voids_result *res,
                               cdem_error *err) {
    if (!s || !res)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "voids: NULL argument");
    if (!(window > 0.0) || !isfinite(window))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "voids: window = %g m: must be a number > 0",
                         window);
    memset(res, 0, sizeof *res);
    res->window = window;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    double rmin = INFINITY, rmax = 0.0;
    for (size_t i = 0; i < s->n; i++) {
        if (!cdem_surface_is_free(s, i))
            continue;
        const double r = s->radius[i];
        xmin = fmin(xmin, s->x[i] - r);
        xmax = fmax(xmax, s->x[i] + r);
        ymin = fmin(ymin, s->y[i] - r);
        ymax = fmax(ymax, s->y[i] + r);
        rmin = fmin(rmin, r);
        rmax = fmax(rmax, r);
    }
    if (!(rmax > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "voids: the increment has no free element");
    /* a slope over less than an element's diameter is the shape of one element, and would
     * make the surface's cells (h <= window) and columns (r_max / h cells) unbounded */
    if (window < 2.0 * rmax)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "voids: window = %g m: must be at least the largest element's diameter "
                         "(%g m)",
                         window, 2.0 * rmax);
    res->min_clearance = rmax;
    if (steepest_slope(s, xmin, xmax, rmax, res) != 0)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "voids: out of memory for the surface's columns");

    const double fx0 = xmin, fx1 = xmax, fy0 = ymin, fy1 = ymax; /* the free elements' box */
    /* the raster spans every element (walls and faults too) with a margin of 3 rmax + 2 cells
     * all round, so that the sky reaches down beside the walls and below the base */
    for (size_t i = 0; i < s->n; i++)
        if (isfinite(s->x[i]) && isfinite(s->y[i]) && s->radius[i] > 0.0) {
            xmin = fmin(xmin, s->x[i] - s->radius[i]);
            xmax = fmax(xmax, s->x[i] + s->radius[i]);
            ymin = fmin(ymin, s->y[i] - s->radius[i]);
            ymax = fmax(ymax, s->y[i] + s->radius[i]);
        }
    double h = 0.25 * rmin;
    const double span = (xmax - xmin + 4.0 * rmax) * (ymax - ymin + 4.0 * rmax);
    if (span / (h * h) > VOIDS_MAX_CELLS)
        h = sqrt(span / VOIDS_MAX_CELLS);
    res->cell = h;
    const long pad = (long)ceil(3.0 * rmax / h) + 2; /* the big probe passes beside the walls */
    xmin -= (double)pad * h;
    ymin -= (double)pad * h;
    const long nx = (long)ceil((xmax - xmin) / h) + 1 + pad;
    const long ny = (long)ceil((ymax - ymin) / h) + 1 + pad;
    const size_t nc = (size_t)nx * (size_t)ny;
    uint8_t *g = calloc(nc, 1);
    float *d = malloc(nc * sizeof *d);
    long *stack = malloc(nc * sizeof *stack);
    if (!g || !d || !stack) {
        free(g);
        free(d);
        free(stack);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "voids: out of memory for a %ld x %ld raster", nx,
                         ny);
    }
    for (size_t i = 0; i < s->n; i++) {
        if (!(isfinite(s->x[i]) && isfinite(s->y[i]) && s->radius[i] > 0.0))
            continue;
        paint(g, nx, ny, xmin, ymin, h, s->x[i], s->y[i], s->radius[i],
              cdem_surface_is_free(s, i) ? CELL_FREE : CELL_BOUNDARY);
    }
    uint8_t *near = malloc(nc);
    if (!near) {
        free(g);
        free(d);
        free(stack);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "voids: out of memory for a %ld x %ld raster", nx,
                         ny);
    }
    clearance(g, nx, ny, d, near);
    /* bits of m: what a disc of radius rmax reaches from the sky, the cells deep enough for
     * a void that it does not reach, and those already counted */
    enum { OUTSIDE = 1, DEEP = 2, SEEN = 4 };
    uint8_t *m = calloc(nc, 1);
    if (!m) {
        free(near);
        free(g);
        free(d);
        free(stack);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "voids: out of memory for a %ld x %ld raster", nx,
                         ny);
    }
    const float big = (float)(rmax / h);
    reach_from_sky(d, m, OUTSIDE, nx, ny, big, stack);
    for (long j = 0; j < ny; j++)
        for (long i = 0; i < nx; i++) {
            const long c = j * nx + i;
            if (g[c] != CELL_EMPTY || (m[c] & OUTSIDE))
                continue;
            if (d[c] >= big)
                m[c] |= DEEP;
            /* the largest clearance of the inside, within the free elements' box */
            const double cx = xmin + (i + 0.5) * h, cy = ymin + (j + 0.5) * h;
            if (cx >= fx0 && cx <= fx1 && cy >= fy0 && cy <= fy1 && near[c] == CELL_FREE &&
                d[c] > res->largest_clearance / h) {
                res->largest_clearance = d[c] * h;
                res->largest_x = cx;
                res->largest_y = cy;
            }
        }
    /* a void: a region of deep cells in the rock mass whose room for the centre of an element
     * of radius rmax spans at least a disc of rmax / 4 (a cavity of 1.25 rmax or more; the
     * pockets where an element barely fits between others are smaller) */
    const double min_room = M_PI * 0.0625 * rmax * rmax;
    res->void_min_room = min_room;
    long jlo, jhi;
    int rock;
    for (long c = 0; c < nx * ny; c++) {
        if (!(m[c] & DEEP) || (m[c] & SEEN))
            continue;
        const double room =
            (double)region(m, near, DEEP, SEEN, nx, ny, c, stack, &jlo, &jhi, &rock) * h * h;
        if (rock && room >= min_room) {
            res->n_voids++;
            res->void_area += room;
        }
    }
    fissures(g, nx, ny, h, xmin, ymin, rmax, res);
    free(m);
    free(near);
    free(g);
    free(d);
    free(stack);
    return CDEM_OK;
}
