/* assembly: see assembly.h and docs/assembly.md.
 *
 * Packing by sequential deposition (Visscher & Bolsterli 1972, in 2-D): a disc of a random
 * radius class is dropped at a random x; it falls until it meets a disc (or the base), then
 * rolls over that disc, downhill, until it meets a second disc, a lateral wall or the base.
 * If the two contacts hold it against gravity it stops; otherwise it rolls on over the new
 * disc, or falls again when it passes the equator of the disc it rolls on. Stops are exact
 * tangencies, so the packing has no overlap. A disc whose lowest point rests above the
 * assembly height is discarded; filling stops after a run of consecutive discards (the
 * region below the height is then saturated). The cell grid (common/grid.h: cells of 2 x max
 * radius, one linked list per cell as the discs arrive one by one, plus the highest centre
 * per grid column) makes every drop O(1), so building N discs is O(N). Everything lives in
 * a `packer` context local to the call.
 */
#include "assembly.h"

#include "grid.h"
#include "surface.h"

#include <gsl/gsl_rng.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Radius classes are drawn from a shuffled "bag" holding each class as many times as its
 * share (CDEM_RADIUS_SHARES, solver/base/model.h): the composition is then exact to within one
 * bag instead of carrying binomial noise (about 2 % in the element count of a 10 x 5 unit
 * assembly with independent draws). */
static const int bag_counts[CDEM_NUM_RADII] = CDEM_RADIUS_SHARES;
#define ASM_BAG_SIZE CDEM_RADIUS_SHARES_TOTAL

/* Consecutive discarded drops that end the filling: at least ASM_MIN_FAILS, and
 * ASM_FAILS_PER_DIAMETER per smallest diameter of width (so a wide box is tried as
 * thoroughly as a narrow one). */
#define ASM_MIN_FAILS          200
#define ASM_FAILS_PER_DIAMETER 4.0

/* Moves (falls + rolls) one drop may take before it is discarded (never reached in
 * practice; a guard against a numerical cycle). */
#define ASM_MAX_MOVES 1000

/* The packer numbers its discs and cells with 32-bit integers (head, next; the grid's
 * cdem_grid_sort), so an assembly that could hold more discs or cells than ASM_MAX_INDEX is
 * refused. The bound it is checked against is the densest packing of the smallest discs
 * (0.9069 of the area, every disc of radius[0]): a true upper bound, but about 2.7 times the
 * real count, since the bag's mix (4:3:2:1 of 1, 1.5, 2 and 2.5 x radius[0]) has a mean disc
 * area of 2.5 x the smallest's and the deposition fills about 0.82 of the area. Any other
 * limit on the size of a model is the memory of the machine (cdem_run_check_memory,
 * solver/run/run.h), checked before the assembly is built. */
#define ASM_MAX_INDEX 2147483647.0

/* The arrays of the discs start at the expected count (the mix's mean disc area at
 * ASM_FILL_GUESS of the box) and grow by half when it is reached. */
#define ASM_FILL_GUESS 0.9
/* The area fraction the deposition fills (about 0.82: cdem_assembly_info.area_fraction of the
 * default assembly), for the expected count the refusal names. */
#define ASM_FILL_SEEN 0.82

/* Relative tolerance of a tangency, as a fraction of the contact distance. */
#define ASM_EPS 1e-12

/* Relative gap (of the contact distance, or of r for walls) below which two surfaces count
 * as touching at the start of a move; covers round-off at 1e5 m coordinates. */
#define TOUCH_TOL 1e-9

typedef struct {
    double w, h;       /* box: inner width and assembly height, m, > 0 */
    double rmax;       /* largest radius, m */
    cdem_grid grid;    /* cells of 2 x rmax from the origin (common/grid.h) */
    int ncols, nrows;  /* grid.nx, grid.ny as int, >= 1 */
    int *head;         /* [ncols * nrows] first disc of each cell, -1 if empty */
    int *next;         /* [cap] next disc of the same cell, -1 at the end */
    double *coltop;    /* [ncols] highest centre y of any disc in the grid column, m (-1 empty) */
    double *x, *y, *r; /* [cap] disc centres and radii, m */
    int *cls;          /* [cap] radius class 0..3 */
    long n, cap;       /* discs placed; capacity of the arrays */
    long n_guard;      /* drops discarded by a numerical guard (see settle), >= 0 */
} packer;

typedef enum { ROLL_STOP, ROLL_FALL, ROLL_HIT } roll_event;

/* The grid column of x and row of y, clamped into the grid. */
static int col_of(const packer *pk, double x) {
    return (int)cdem_grid_col(&pk->grid, x);
}

static int row_of(const packer *pk, double y) {
    return (int)cdem_grid_row(&pk->grid, y);
}

static void packer_free(packer *pk) {
    free(pk->head);
    free(pk->next);
    free(pk->coltop);
    free(pk->x);
    free(pk->y);
    free(pk->r);
    free(pk->cls);
    memset(pk, 0, sizeof *pk);
}

static void packer_insert(packer *pk, double x, double y, double r, int cls) {
    long i = pk->n++;
    pk->x[i] = x;
    pk->y[i] = y;
    pk->r[i] = r;
    pk->cls[i] = cls;
    int c = col_of(pk, x);
    int cell = row_of(pk, y) * pk->ncols + c;
    pk->next[i] = pk->head[cell];
    pk->head[cell] = (int)i;
    if (y > pk->coltop[c])
        pk->coltop[c] = y;
}

/* Vertical fall of a disc of radius r at x from height y_from (HUGE_VAL: from above
 * everything). Returns the height where it first touches a disc (index in *support) or the
 * base (*support = -1). Disc `exclude` (the disc just rolled off) is ignored. */
static double fall(const packer *pk, double x, double y_from, double r, long exclude,
                   long *support) {
    double best = r; /* resting on the base */
    long sup = -1;
    int c0 = col_of(pk, x - r - pk->rmax), c1 = col_of(pk, x + r + pk->rmax);
    double top = -1.0;
    for (int c = c0; c <= c1; c++)
        top = fmax(top, pk->coltop[c]);
    if (top < 0.0) {
        *support = -1;
        return best;
    }
    for (int row = row_of(pk, fmin(y_from, top)); row >= 0; row--) {
        if ((row + 1) * pk->grid.cell + r + pk->rmax < best)
            break; /* no disc of this row or below can be met higher */
        for (int c = c0; c <= c1; c++) {
            for (int k = pk->head[row * pk->ncols + c]; k >= 0; k = pk->next[k]) {
                if (k == exclude)
                    continue;
                double d = r + pk->r[k], dx = pk->x[k] - x;
                if (dx * dx >= d * d * (1.0 - ASM_EPS))
                    continue; /* not under the falling disc (or only grazing it) */
                double h = pk->y[k] + sqrt(d * d - dx * dx);
                if (h > y_from) {
                    /* k's top contact is above the start: k lies above (not met on the way
                     * down), or the disc touches it now (round-off): met at once */
                    if (pk->y[k] < y_from && h <= y_from + 1e-6 * d)
                        h = y_from;
                    else
                        continue;
                }
                if (h <= best)
                    continue;
                best = h;
                sup = k;
            }
        }
    }
    *support = sup;
    return best;
}

/* Rolls a disc of radius r at (*x, *y), touching disc j, around j in direction dir (+1:
 * to the right, -1: to the left), downhill. Moves it to the first event: ROLL_STOP (it met
 * the base or the wall it rolls towards: stable), ROLL_HIT (it met disc *hit) or ROLL_FALL
 * (it reached j's equator, or starts at or below it: free fall from there). A disc or wall
 * it already touches and would push into stops it at once (t = 0): this makes the ties at
 * a tangency (met exactly at j's equator, landed beside a disc) safe. */
static roll_event roll(const packer *pk, double *x, double *y, double r, long j, int dir,
                       long *hit) {
    const double xj = pk->x[j], yj = pk->y[j], d = r + pk->r[j];
    const double px0 = *x, py0 = *y;
    const double th0 = atan2(py0 - yj, px0 - xj);
    *hit = -1;
    if (th0 <= 0.0)
        return ROLL_FALL; /* at or below the equator of j: j does not hold it */
    double tmax = dir > 0 ? th0 : M_PI - th0;
    if (tmax <= 0.0)
        return ROLL_FALL;
    /* already on the base or against the wall ahead */
    if (py0 <= r * (1.0 + TOUCH_TOL) ||
        (dir > 0 ? px0 >= pk->w - r * (1.0 + TOUCH_TOL) : px0 <= r * (1.0 + TOUCH_TOL)))
        return ROLL_STOP;
    /* events up to a hair past the equator count (an exact tie goes to the contact) */
    double tbest = tmax * (1.0 + 1e-9) + 1e-12;
    roll_event ev = ROLL_FALL;
    long who = -1;

    /* the base, y = r */
    double s = (r - yj) / d;
    if (s > -1.0 && s < 1.0) {
        double th = dir > 0 ? asin(s) : M_PI - asin(s);
        double t = dir > 0 ? th0 - th : th - th0;
        if (t > 0.0 && t < tbest) {
            tbest = t;
            ev = ROLL_STOP;
        }
    }
    /* the lateral wall ahead: x = w - r (right) or x = r (left) */
    double cw = dir > 0 ? (pk->w - r - xj) / d : (r - xj) / d;
    if (cw > -1.0 && cw < 1.0) {
        double th = acos(cw);
        double t = dir > 0 ? th0 - th : th - th0;
        if (t > 0.0 && t < tbest) {
            tbest = t;
            ev = ROLL_STOP;
        }
    }
    /* other discs: intersections of the circle of radius d around j with the circle of
     * radius r + r_k around k, entered (not left) while rolling */
    const double v0x = dir > 0 ? sin(th0) : -sin(th0), v0y = dir > 0 ? -cos(th0) : cos(th0);
    double reach = d + r + pk->rmax;
    int c0 = col_of(pk, xj - reach), c1 = col_of(pk, xj + reach);
    int r0 = row_of(pk, yj - reach), r1 = row_of(pk, yj + reach);
    for (int row = r0; row <= r1; row++) {
        for (int c = c0; c <= c1; c++) {
            for (int k = pk->head[row * pk->ncols + c]; k >= 0; k = pk->next[k]) {
                if (k == j)
                    continue;
                double D = r + pk->r[k];
                double ex = pk->x[k] - px0, ey = pk->y[k] - py0;
                if (ex * ex + ey * ey <= D * D * (1.0 + TOUCH_TOL) && ex * v0x + ey * v0y > 0.0) {
                    /* touching k now and rolling into it */
                    *hit = k;
                    return ROLL_HIT;
                }
                double dkx = pk->x[k] - xj, dky = pk->y[k] - yj;
                double L = sqrt(dkx * dkx + dky * dky);
                if (L >= d + D || L <= fabs(d - D))
                    continue;
                double alpha = atan2(dky, dkx);
                double cb = (d * d + L * L - D * D) / (2.0 * d * L);
                double beta = acos(fmax(-1.0, fmin(1.0, cb)));
                for (int sgn = -1; sgn <= 1; sgn += 2) {
                    double th = alpha + sgn * beta;
                    double t = dir > 0 ? th0 - th : th - th0;
                    while (t <= -M_PI)
                        t += 2.0 * M_PI;
                    while (t > M_PI)
                        t -= 2.0 * M_PI;
                    if (!(t > 0.0 && t < tbest))
                        continue;
                    /* entering k: the motion at the meeting point points towards k */
                    double px = xj + d * cos(th), py = yj + d * sin(th);
                    double vx = dir > 0 ? sin(th) : -sin(th);
                    double vy = dir > 0 ? -cos(th) : cos(th);
                    if ((pk->x[k] - px) * vx + (pk->y[k] - py) * vy <= 0.0)
                        continue;
                    tbest = t;
                    ev = ROLL_HIT;
                    who = k;
                }
            }
        }
    }
    if (ev == ROLL_FALL) { /* exactly at the equator */
        *x = xj + dir * d;
        *y = yj;
        return ev;
    }
    double th = dir > 0 ? th0 - tbest : th0 + tbest;
    *x = xj + d * cos(th);
    *y = yj + d * sin(th);
    if (ev == ROLL_STOP && *y < r)
        *y = r;
    *hit = who;
    return ev;
}

/* A disc at (x, y) touching discs j and k is held against gravity when the upward vertical
 * lies in the cone of the two contact normals. */
static int stable_on(const packer *pk, double x, double y, long j, long k) {
    double ajx = x - pk->x[j], ajy = y - pk->y[j];
    double akx = x - pk->x[k], aky = y - pk->y[k];
    double det = ajx * aky - ajy * akx;
    if (fabs(det) <= ASM_EPS * (ajx * ajx + ajy * ajy + akx * akx + aky * aky))
        return 0;
    double a = -akx / det, b = ajx / det;
    return a >= 0.0 && b >= 0.0;
}

/* 1 when a disc at (x, y) rolling around disc a in direction dir moves away from (or
 * tangentially to) disc b's centre, i.e. does not push into b. */
static int rolls_away(const packer *pk, double x, double y, long a, int dir, long b) {
    double th = atan2(y - pk->y[a], x - pk->x[a]);
    double vx = dir > 0 ? sin(th) : -sin(th), vy = dir > 0 ? -cos(th) : cos(th);
    return (x - pk->x[b]) * vx + (y - pk->y[b]) * vy >= 0.0;
}

/* 1 when a disc of radius r at (x, y) overlaps no placed disc by more than the tolerance. */
static int free_of_overlap(const packer *pk, double x, double y, double r) {
    double reach = r + pk->rmax;
    int c0 = col_of(pk, x - reach), c1 = col_of(pk, x + reach);
    int r0 = row_of(pk, y - reach), r1 = row_of(pk, y + reach);
    for (int row = r0; row <= r1; row++)
        for (int c = c0; c <= c1; c++)
            for (int k = pk->head[row * pk->ncols + c]; k >= 0; k = pk->next[k]) {
                double D = r + pk->r[k], dx = pk->x[k] - x, dy = pk->y[k] - y;
                if (dx * dx + dy * dy < D * D * (1.0 - 1e-9))
                    return 0;
            }
    return x >= r * (1.0 - 1e-9) && x <= pk->w - r * (1.0 - 1e-9) && y >= r * (1.0 - 1e-9);
}

/* Drops one disc of radius r at x0 and lets it settle. Returns 1 with its rest position
 * in (*x, *y), or 0 when it found none (numerical guard). */
static int settle(const packer *pk, gsl_rng *rng, double x0, double r, double *x, double *y) {
    double px = x0, py = HUGE_VAL;
    long exclude = -1;
    for (int moves = 0; moves < ASM_MAX_MOVES;) {
        long j;
        py = fall(pk, px, py, r, exclude, &j);
        moves++;
        if (j < 0)
            goto rest; /* on the base */
        int dir = px > pk->x[j] ? 1 : (px < pk->x[j] ? -1 : (gsl_rng_uniform(rng) < 0.5 ? -1 : 1));
        int falling = 0;
        while (!falling && moves < ASM_MAX_MOVES) {
            long k;
            roll_event ev = roll(pk, &px, &py, r, j, dir, &k);
            moves++;
            if (ev == ROLL_STOP)
                goto rest;
            if (ev == ROLL_FALL) {
                exclude = j;
                falling = 1;
                break;
            }
            if (stable_on(pk, px, py, j, k))
                goto rest;
            /* not held: roll on over k, downhill, which must take it away from j */
            int dk = px > pk->x[k] ? 1 : (px < pk->x[k] ? -1 : dir);
            if (!rolls_away(pk, px, py, k, dk, j))
                return 0; /* wedged between j and k without support: discard */
            dir = dk;
            j = k;
        }
        if (!falling)
            return 0; /* move limit while rolling */
    }
    return 0; /* move limit */
rest:
    if (!free_of_overlap(pk, px, py, r))
        return 0;
    *x = px;
    *y = py;
    return 1;
}

/* The class bag: refilled and shuffled (Fisher-Yates) whenever it is empty. */
typedef struct {
    int slot[ASM_BAG_SIZE]; /* radius classes 0..3 */
    int left;               /* classes not yet drawn, 0..ASM_BAG_SIZE */
} class_bag;

static int draw_class(class_bag *bag, gsl_rng *rng) {
    if (bag->left == 0) {
        int n = 0;
        for (int c = 0; c < CDEM_NUM_RADII; c++)
            for (int k = 0; k < bag_counts[c]; k++)
                bag->slot[n++] = c;
        for (int i = n - 1; i > 0; i--) {
            int j = (int)gsl_rng_uniform_int(rng, (unsigned long)i + 1);
            int t = bag->slot[i];
            bag->slot[i] = bag->slot[j];
            bag->slot[j] = t;
        }
        bag->left = n;
    }
    return bag->slot[--bag->left];
}

/* Orders the discs row-major by grid cell (bottom row first), then by y, x. */
typedef struct {
    long key;    /* row * ncols + col */
    double y, x; /* centre, m (ties inside a cell) */
    long i;      /* index in the packer */
} sort_item;

static int cmp_item(const void *pa, const void *pb) {
    const sort_item *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    if (a->y != b->y)
        return a->y < b->y ? -1 : 1;
    if (a->x != b->x)
        return a->x < b->x ? -1 : 1;
    return a->i < b->i ? -1 : (a->i > b->i);
}

/* The mean area of a disc of the bag's mix, m^2. */
static double mean_disc_area(const cdem_model *m) {
    double sum = 0.0;
    for (int c = 0; c < CDEM_NUM_RADII; c++)
        sum += bag_counts[c] * M_PI * m->radius[c] * m->radius[c];
    return sum / ASM_BAG_SIZE;
}

static cdem_status check_geometry(const cdem_params *p, const cdem_model *m, cdem_error *err);

static cdem_status check_inputs(const cdem_params *p, const cdem_model *m, const cdem_state *s,
                                cdem_error *err) {
    if (!p || !m || !s)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_assembly_build: NULL %s",
                         !p ? "params" : (!m ? "model" : "state"));
    if (s->n != 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_assembly_build: the state already holds %zu elements; it must be "
                         "initialised and empty",
                         s->n);
    return check_geometry(p, m, err);
}

/* The sizes, radii and masses the packing needs, and the limit of its indices. */
static cdem_status check_geometry(const cdem_params *p, const cdem_model *m, cdem_error *err) {
    if (!(isfinite(p->unit_scaling) && p->unit_scaling > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "assembly.unit_scaling = %g m: must be finite and > 0 (100-1000)",
                         p->unit_scaling);
    if (!(isfinite(p->width) && p->width > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "assembly.width = %g units: must be finite and > 0 (10-100)", p->width);
    if (!(isfinite(p->height) && p->height > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "assembly.height = %g units: must be finite and > 0 (2.5-7.5)", p->height);
    if (!(p->base_spacing >= 1.0 && p->base_spacing <= 2.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "assembly.base_spacing = %g wall radii: must be 1-2 (1 overlapping, "
                         "2 touching)",
                         p->base_spacing);
    if (p->wall_height_multiplier < 1 || p->wall_height_multiplier > 4)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "assembly.wall_height_multiplier = %d: must be 1-4",
                         p->wall_height_multiplier);
    for (int c = 0; c < CDEM_NUM_RADII; c++) {
        if (!(isfinite(m->radius[c]) && m->radius[c] > 0.0))
            return CDEM_FAIL(err, CDEM_ERR_RANGE, "model radius[%d] = %g m: must be finite and > 0",
                             c, m->radius[c]);
        if (c > 0 && m->radius[c] < m->radius[c - 1])
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "model radius[%d] = %g m is smaller than radius[%d] = %g m: radii "
                             "must be ascending",
                             c, m->radius[c], c - 1, m->radius[c - 1]);
        if (!(isfinite(m->mass[c]) && m->mass[c] > 0.0))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "model mass[%d] = %g kg/m: must be finite and > 0", c, m->mass[c]);
    }
    double w = p->width * p->unit_scaling, h = p->height * p->unit_scaling;
    double rmin = m->radius[0], rmax = m->radius[CDEM_NUM_RADII - 1];
    if (w < 4.0 * rmax || h < 2.0 * rmax)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "assembly of %g x %g m is too small for the largest element radius "
                         "%g m: width must be >= 4 and height >= 2 radii",
                         w, h, rmax);
    /* densest disc packing (pi / sqrt 12) of the smallest discs bounds the count */
    double bound = 0.9069 * w * (h + 2.0 * rmax) / (M_PI * rmin * rmin) +
                   2.0 * (w + 2.0 * p->wall_height_multiplier * h) / rmin;
    double cells = (w / (2.0 * rmax) + 2.0) * (h / (2.0 * rmax) + 4.0);
    if (bound > ASM_MAX_INDEX || cells > ASM_MAX_INDEX)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "assembly of %g x %g m with smallest radius %g m could hold up to %.3g "
                         "elements (the densest packing of its smallest discs; about %.3g "
                         "expected) in %.3g grid cells: more than the %.0f the packing's 32-bit "
                         "indices can number; use larger elements ([assembly] radius_scale) or "
                         "a smaller assembly",
                         w, h, rmin, bound, ASM_FILL_SEEN * w * h / mean_disc_area(m), cells,
                         ASM_MAX_INDEX);
    return CDEM_OK;
}

cdem_status cdem_assembly_check(const cdem_params *p, const cdem_model *m, cdem_error *err) {
    if (!p || !m)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_assembly_check: NULL %s",
                         !p ? "params" : "model");
    return check_geometry(p, m, err);
}

static cdem_status packer_alloc(packer *pk, double w, double h, const cdem_model *m,
                                cdem_error *err) {
    const double rmax = m->radius[CDEM_NUM_RADII - 1];
    memset(pk, 0, sizeof *pk);
    pk->w = w;
    pk->h = h;
    pk->rmax = rmax;
    const double cell = 2.0 * rmax;
    pk->ncols = (int)ceil(w / cell) + 1;
    pk->nrows = (int)ceil((h + 2.0 * rmax) / cell) + 2;
    pk->grid = (cdem_grid){
        .x0 = 0.0, .y0 = 0.0, .cell = cell, .nx = (size_t)pk->ncols, .ny = (size_t)pk->nrows};
    pk->cap = (long)(ASM_FILL_GUESS * w * (h + 2.0 * rmax) / mean_disc_area(m)) + 16;
    size_t ncell = (size_t)pk->ncols * (size_t)pk->nrows;
    pk->head = malloc(ncell * sizeof *pk->head);
    pk->coltop = malloc((size_t)pk->ncols * sizeof *pk->coltop);
    pk->next = malloc((size_t)pk->cap * sizeof *pk->next);
    pk->x = malloc((size_t)pk->cap * sizeof *pk->x);
    pk->y = malloc((size_t)pk->cap * sizeof *pk->y);
    pk->r = malloc((size_t)pk->cap * sizeof *pk->r);
    pk->cls = malloc((size_t)pk->cap * sizeof *pk->cls);
    if (!pk->head || !pk->coltop || !pk->next || !pk->x || !pk->y || !pk->r || !pk->cls) {
        packer_free(pk);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM,
                         "out of memory allocating the packing grid (%zu cells, %ld discs)", ncell,
                         pk->cap);
    }
    for (size_t i = 0; i < ncell; i++)
        pk->head[i] = -1;
    for (int c = 0; c < pk->ncols; c++)
        pk->coltop[c] = -1.0;
    return CDEM_OK;
}

/* Grows the disc arrays by half (0: out of memory; the arrays are kept). */
static int packer_grow(packer *pk) {
    const long cap = pk->cap + pk->cap / 2 + 16;
    int *next = realloc(pk->next, (size_t)cap * sizeof *next);
    if (next)
        pk->next = next;
    double *x = realloc(pk->x, (size_t)cap * sizeof *x);
    if (x)
        pk->x = x;
    double *y = realloc(pk->y, (size_t)cap * sizeof *y);
    if (y)
        pk->y = y;
    double *r = realloc(pk->r, (size_t)cap * sizeof *r);
    if (r)
        pk->r = r;
    int *cls = realloc(pk->cls, (size_t)cap * sizeof *cls);
    if (cls)
        pk->cls = cls;
    if (!next || !x || !y || !r || !cls)
        return 0;
    pk->cap = cap;
    return 1;
}

/* Fills the box up to height h (centres at or below h). */
static cdem_status pack(packer *pk, const cdem_model *m, gsl_rng *rng, long max_fails,
                        cdem_error *err) {
    long fails = 0;
    class_bag bag = {.left = 0};
    while (fails < max_fails) {
        int cls = draw_class(&bag, rng);
        double r = m->radius[cls];
        double x0 = r + gsl_rng_uniform(rng) * (pk->w - 2.0 * r);
        double x, y;
        if (!settle(pk, rng, x0, r, &x, &y)) {
            pk->n_guard++;
            fails++;
            continue;
        }
        if (y - r > pk->h) {
            fails++;
            continue;
        }
        if (pk->n == pk->cap && !packer_grow(pk))
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory growing the packing to %ld discs",
                             pk->cap + pk->cap / 2 + 16);
        packer_insert(pk, x, y, r, cls);
        fails = 0;
    }
    return CDEM_OK;
}

/* The base's centre spacing in wall radii: assembly.base_spacing, unless the mode decides it
 * (the biaxial test's smooth bottom platen: its derive hook). */
static double base_spacing_of(const cdem_params *p, const cdem_model *m) {
    return m->mode.base_spacing > 0.0 ? m->mode.base_spacing : p->base_spacing;
}

/* Number of base discs: from x = -rw to w + rw with centres at most spacing * rw apart. */
static long base_disc_count(double w, double rw, double spacing) {
    return (long)ceil((w + 2.0 * rw) / (spacing * rw)) + 1;
}

/* In the repose test the base runs on past each lateral wall that the mode removes, by the
 * assembly's width: the collapsing pile spreads over the base and comes to rest on it,
 * instead of draining over the base's end where the wall stood (which pins the toe there
 * and keeps the slope moving; issue 34, examples/calibration/README.md). Sets the number of
 * extra base discs beyond the left (*left) and the right (*right) wall, spaced like the
 * base (sb): 0 in every other mode. */
/* The discs the base runs on past the left and right walls (the mode's base_beyond_*, in
 * assembly widths; repose: the collapse comes to rest on them instead of draining over the
 * base's end, docs/solver.md), at the base's spacing sb. */
static void base_extension(const cdem_model_mode *mode, double w, double sb, long *left,
                           long *right) {
    *right = mode->base_beyond_right > 0.0 ? (long)ceil(mode->base_beyond_right * w / sb) : 0;
    *left = mode->base_beyond_left > 0.0 ? (long)ceil(mode->base_beyond_left * w / sb) : 0;
}

/* Appends the walls: base (y = -rw, x from -rw to w + rw, centres at most base_spacing * rw
 * apart), left (x = -rw) and right (x = w + rw) walls from just above the base corner up to
 * wall height hw, centres at most rw apart, then the mode's extension of the base past the
 * walls (base_extension; after the lateral walls, so that the other walls keep their
 * indices).
 * The base's spacing sets its roughness: the base has no other way to resist sliding when
 * its friction is zero (Fig. 12). */
static cdem_status append_walls(cdem_state *s, const cdem_model_mode *mode, double w, double hw,
                                double rw, double mw, double base_spacing, long *n_wall,
                                cdem_error *err) {
    long nb = base_disc_count(w, rw, base_spacing);
    double sb = (w + 2.0 * rw) / (double)(nb - 1);
    long nl = (long)ceil((hw + rw) / rw);
    double sl = (hw + rw) / (double)nl;
    long ext_left, ext_right;
    base_extension(mode, w, sb, &ext_left, &ext_right);
    CDEM_TRY(cdem_state_reserve(s, s->n + (size_t)(nb + 2 * nl + ext_left + ext_right), err));
    for (long i = 0; i < nb; i++)
        CDEM_TRY(cdem_state_append(s, -1, -rw + (double)i * sb, -rw, rw, mw, 0,
                                   CDEM_FLAG_WALL | CDEM_FLAG_BASE, 0, NULL, err));
    for (int side = 0; side < 2; side++) {
        double xw = side == 0 ? -rw : w + rw;
        for (long i = 1; i <= nl; i++)
            CDEM_TRY(cdem_state_append(s, -1, xw, -rw + (double)i * sl, rw, mw, 0, CDEM_FLAG_WALL,
                                       0, NULL, err));
    }
    for (long i = 1; i <= ext_right; i++)
        CDEM_TRY(cdem_state_append(s, -1, w + rw + (double)i * sb, -rw, rw, mw, 0,
                                   CDEM_FLAG_WALL | CDEM_FLAG_BASE, 0, NULL, err));
    for (long i = 1; i <= ext_left; i++)
        CDEM_TRY(cdem_state_append(s, -1, -rw - (double)i * sb, -rw, rw, mw, 0,
                                   CDEM_FLAG_WALL | CDEM_FLAG_BASE, 0, NULL, err));
    *n_wall = nb + 2 * nl + ext_left + ext_right;
    return CDEM_OK;
}

static cdem_status fill_state(const packer *pk, const cdem_params *p, const cdem_model *m,
                              cdem_state *s, cdem_assembly_info *info, cdem_error *err) {
    sort_item *items = malloc((size_t)(pk->n ? pk->n : 1) * sizeof *items);
    if (!items)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory sorting %ld elements", pk->n);
    for (long i = 0; i < pk->n; i++) {
        items[i].key = (long)row_of(pk, pk->y[i]) * pk->ncols + col_of(pk, pk->x[i]);
        items[i].y = pk->y[i];
        items[i].x = pk->x[i];
        items[i].i = i;
    }
    qsort(items, (size_t)pk->n, sizeof *items, cmp_item);
    cdem_status st = cdem_state_reserve(s, (size_t)pk->n, err);
    double area = 0.0;
    for (long q = 0; q < pk->n && st == CDEM_OK; q++) {
        long i = items[q].i;
        int c = pk->cls[i];
        area += M_PI * pk->r[i] * pk->r[i];
        st =
            cdem_state_append(s, -1, pk->x[i], pk->y[i], pk->r[i], m->mass[c], 0, 0u, 0, NULL, err);
    }
    free(items);
    CDEM_TRY(st);
    long n_wall = 0;
    double rw = m->radius[0];
    CDEM_TRY(append_walls(s, &m->mode, pk->w, p->wall_height_multiplier * pk->h, rw, m->mass[0],
                          base_spacing_of(p, m), &n_wall, err));
    if (info) {
        memset(info, 0, sizeof *info);
        info->n_internal = pk->n;
        info->n_wall = n_wall;
        info->n_guard_discards = pk->n_guard;
        info->wall_radius = rw;
        info->wall_spacing = rw;
        info->base_spacing =
            (pk->w + 2.0 * rw) / (double)(base_disc_count(pk->w, rw, base_spacing_of(p, m)) - 1);
        info->area_fraction = area / (pk->w * pk->h);
        /* top profile: the surface (common/surface.h) in the grid's columns */
        size_t *col_top = malloc(pk->grid.nx * sizeof *col_top);
        if (!col_top)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for %zu surface columns",
                             pk->grid.nx);
        cdem_surface_columns(s, &pk->grid, CDEM_SURFACE_BY_TOP, -INFINITY, INFINITY, col_top);
        double sum = 0.0, top_max = 0.0;
        int used = 0;
        for (size_t c = 0; c < pk->grid.nx; c++) {
            if (col_top[c] == SIZE_MAX)
                continue;
            const double top = s->y[col_top[c]] + s->radius[col_top[c]];
            sum += top;
            used++;
            top_max = fmax(top_max, top);
        }
        free(col_top);
        info->top_mean = used ? sum / used : 0.0;
        info->top_max = top_max;
    }
    return CDEM_OK;
}

cdem_status cdem_assembly_build(const cdem_params *p, const cdem_model *m, cdem_state *s,
                                cdem_assembly_info *info, cdem_error *err) {
    if (info)
        memset(info, 0, sizeof *info);
    CDEM_TRY(check_inputs(p, m, s, err));
    double w = p->width * p->unit_scaling, h = p->height * p->unit_scaling;
    double rmin = m->radius[0];
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory allocating the random generator");
    gsl_rng_set(rng, (unsigned long)p->seed);
    packer pk;
    cdem_status st = packer_alloc(&pk, w, h, m, err);
    if (st != CDEM_OK) {
        gsl_rng_free(rng);
        return st;
    }
    double fails = fmax(ASM_MIN_FAILS, ASM_FAILS_PER_DIAMETER * w / (2.0 * rmin));
    st = pack(&pk, m, rng, (long)fails, err);
    gsl_rng_free(rng);
    if (st != CDEM_OK) {
        packer_free(&pk);
        return st;
    }
    st = fill_state(&pk, p, m, s, info, err);
    packer_free(&pk);
    if (st != CDEM_OK)
        s->n = 0;
    return st;
}

cdem_status cdem_assembly_count(const cdem_params *p, const cdem_model *m, long *n_internal,
                                long *n_wall, cdem_error *err) {
    cdem_state s;
    CDEM_TRY(cdem_state_init(&s, 0, 0, err));
    cdem_assembly_info info;
    cdem_status st = cdem_assembly_build(p, m, &s, &info, err);
    cdem_state_free(&s);
    CDEM_TRY(st);
    if (n_internal)
        *n_internal = info.n_internal;
    if (n_wall)
        *n_wall = info.n_wall;
    return CDEM_OK;
}
