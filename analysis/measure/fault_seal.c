/* fault_seal: see fault_seal.h. */
#include "fault_seal.h"

#include "surface.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Sides: 0 the -x side of the line (left), 1 the +x side (right). */
typedef struct {
    int max_layer;
    double *top[2];    /* [layer]: highest y + r of the layer's sampled elements, -inf if none */
    double *bottom[2]; /* [layer]: lowest y - r, +inf if none */
} side_layers;

void cdem_fault_seal_free(cdem_fault_seal_result *res) {
    if (!res)
        return;
    free(res->horizon);
    free(res->row);
    free(res->seal);
    memset(res, 0, sizeof *res);
}

static int takes_part(const cdem_state *s, size_t i) {
    return cdem_surface_is_free(s, i) && s->layer[i] >= 1;
}

static int cmp_double(const void *a, const void *b) {
    const double p = *(const double *)a, q = *(const double *)b;
    return (p > q) - (p < q);
}

/* The base of layer L on side k: the top of the next lower layer present there, or the
 * layer's own lowest element bottom when none is below. NAN when L is absent on that side. */
static double layer_base(const side_layers *sl, int k, int L) {
    if (!isfinite(sl->top[k][L]))
        return NAN;
    for (int m = L - 1; m >= 1; m--)
        if (isfinite(sl->top[k][m]))
            return sl->top[k][m];
    return sl->bottom[k][L];
}

/* The layer of side k holding height y in its interval (base, top], 0 when none does. */
static int layer_at(const side_layers *sl, int k, double y) {
    for (int L = 1; L <= sl->max_layer; L++) {
        if (!isfinite(sl->top[k][L]))
            continue;
        if (y > layer_base(sl, k, L) && y <= sl->top[k][L])
            return L;
    }
    return 0;
}

static cdem_status check_inputs(const cdem_state *s, const cdem_seal_zone *z,
                                const int *seal_layers, size_t n_seals, int *lo, int *hi,
                                cdem_error *err) {
    if (!(z->y_top != z->y_bottom) || !isfinite(z->x_top) || !isfinite(z->x_bottom) ||
        !isfinite(z->y_top) || !isfinite(z->y_bottom))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "the fault zone's line needs two points at different heights");
    if (!(z->half_width >= 0.0) || !(z->band > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "the zone's half-width must be >= 0 and its sampling band > 0 (got %g "
                         "and %g m)",
                         z->half_width, z->band);
    *lo = INT32_MAX;
    *hi = 0;
    for (size_t i = 0; i < s->n; i++)
        if (takes_part(s, i)) {
            *lo = s->layer[i] < *lo ? s->layer[i] : *lo;
            *hi = s->layer[i] > *hi ? s->layer[i] : *hi;
        }
    if (*hi == 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "the run has no layers: every free element has layer 0");
    for (size_t k = 0; k < n_seals; k++) {
        int present = 0;
        for (size_t i = 0; i < s->n && !present; i++)
            present = takes_part(s, i) && s->layer[i] == seal_layers[k];
        if (!present)
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "seal layer %d does not exist: the layers are %d..%d", seal_layers[k],
                             *lo, *hi);
    }
    return CDEM_OK;
}

/* Fills sl from the elements sampled on either side of the zone; returns the mean radius
 * of the sampled elements (0 when none). */
static double sample_sides(const cdem_state *s, const cdem_seal_zone *z, side_layers *sl) {
    const double slope = (z->x_top - z->x_bottom) / (z->y_top - z->y_bottom);
    double rsum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (!takes_part(s, i))
            continue;
        const double d = s->x[i] - (z->x_bottom + slope * (s->y[i] - z->y_bottom));
        if (fabs(d) < z->half_width || fabs(d) > z->half_width + z->band)
            continue;
        const int k = d > 0.0, L = s->layer[i];
        const double top = s->y[i] + s->radius[i], bot = s->y[i] - s->radius[i];
        sl->top[k][L] = top > sl->top[k][L] ? top : sl->top[k][L];
        sl->bottom[k][L] = bot < sl->bottom[k][L] ? bot : sl->bottom[k][L];
        rsum += s->radius[i];
        n++;
    }
    return n ? rsum / (double)n : 0.0;
}

static cdem_status measure(const cdem_state *s, const cdem_seal_zone *z, const int *seal_layers,
                           size_t n_seals, double step, side_layers *sl,
                           cdem_fault_seal_result *res, cdem_error *err) {
    const int nl = sl->max_layer;
    const double slope = fabs((z->x_top - z->x_bottom) / (z->y_top - z->y_bottom));
    res->mean_radius = sample_sides(s, z, sl);
    /* the hanging wall: the side whose horizons stand lower */
    double *diff = malloc((size_t)(nl + 1) * sizeof *diff);
    res->horizon = malloc((size_t)(nl + 1) * sizeof *res->horizon);
    if (!diff || !res->horizon) {
        free(diff);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory measuring the fault's throw");
    }
    size_t nd = 0;
    for (int L = 1; L <= nl; L++)
        if (isfinite(sl->top[0][L]) && isfinite(sl->top[1][L]))
            diff[nd++] = sl->top[0][L] - sl->top[1][L];
    if (nd == 0) {
        free(diff);
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "no layer is found on both sides of the fault zone (x %g..%g m): the "
                         "zone or its sampling band of %g m lies outside the layers",
                         fmin(z->x_top, z->x_bottom), fmax(z->x_top, z->x_bottom), z->band);
    }
    qsort(diff, nd, sizeof *diff, cmp_double);
    const double med = nd % 2 ? diff[nd / 2] : 0.5 * (diff[nd / 2 - 1] + diff[nd / 2]);
    res->hanging_wall_right = med >= 0.0;
    const int fw = res->hanging_wall_right ? 0 : 1, hw = 1 - fw;
    for (int L = 1; L <= nl; L++) {
        if (!isfinite(sl->top[fw][L]) || !isfinite(sl->top[hw][L]))
            continue;
        cdem_seal_horizon *h = &res->horizon[res->n_horizons++];
        h->layer = L;
        h->footwall_top = sl->top[fw][L];
        h->hanging_top = sl->top[hw][L];
        h->height = 0.5 * (h->footwall_top + h->hanging_top);
        h->throw_m = h->footwall_top - h->hanging_top;
        h->heave = h->throw_m * slope;
    }
    for (size_t k = 0; k < res->n_horizons; k++)
        diff[k] = res->horizon[k].throw_m;
    qsort(diff, res->n_horizons, sizeof *diff, cmp_double);
    const size_t nh = res->n_horizons;
    res->total_throw = nh % 2 ? diff[nh / 2] : 0.5 * (diff[nh / 2 - 1] + diff[nh / 2]);
    res->total_heave = res->total_throw * slope;
    free(diff);

    /* juxtaposition, every step from the lowest base to the highest top */
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < 2; k++)
        for (int L = 1; L <= nl; L++)
            if (isfinite(sl->top[k][L])) {
                lo = fmin(lo, layer_base(sl, k, L));
                hi = fmax(hi, sl->top[k][L]);
            }
    if (!(step > 0.0))
        step = 0.5 * res->mean_radius;
    const double nrows_d = floor((hi - lo) / step);
    if (!(nrows_d >= 0.0 && nrows_d < 1e7))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "the juxtaposition step %g m gives too many heights over %g m", step,
                         hi - lo);
    const size_t nrows = (size_t)nrows_d + 1;
    res->row = malloc(nrows * sizeof *res->row);
    if (!res->row)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the juxtaposition table");
    for (size_t k = 0; k < nrows; k++) {
        const double y = lo + (k + 0.5) * step;
        if (y > hi)
            break;
        res->row[res->n_rows++] =
            (cdem_seal_juxtaposition){y, layer_at(sl, fw, y), layer_at(sl, hw, y)};
    }

    /* seal layers */
    res->seal = calloc(n_seals ? n_seals : 1, sizeof *res->seal);
    if (!res->seal)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the seal layers");
    for (size_t k = 0; k < n_seals; k++) {
        const int L = seal_layers[k];
        if (!isfinite(sl->top[fw][L]) || !isfinite(sl->top[hw][L]))
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "seal layer %d is not found on the %s side of the fault zone "
                             "(it may be eroded or cut out there)",
                             L, isfinite(sl->top[fw][L]) ? "hanging-wall" : "footwall");
        cdem_seal_layer *q = &res->seal[res->n_seals++];
        q->layer = L;
        q->footwall_base = layer_base(sl, fw, L);
        q->footwall_top = sl->top[fw][L];
        q->hanging_base = layer_base(sl, hw, L);
        q->hanging_top = sl->top[hw][L];
        q->throw_m =
            0.5 * ((q->footwall_top - q->hanging_top) + (q->footwall_base - q->hanging_base));
        q->overlap =
            fmin(q->footwall_top, q->hanging_top) - fmax(q->footwall_base, q->hanging_base);
        q->self_juxtaposed = q->overlap > 0.0;
        q->loss_throw = q->throw_m + q->overlap;
    }
    return CDEM_OK;
}

cdem_status cdem_fault_seal_measure(const cdem_state *s, const cdem_seal_zone *z,
                                    const int *seal_layers, size_t n_seals, double step,
                                    cdem_fault_seal_result *res, cdem_error *err) {
    memset(res, 0, sizeof *res);
    int lo = 0, hi = 0;
    CDEM_TRY(check_inputs(s, z, seal_layers, n_seals, &lo, &hi, err));
    res->lowest_layer = lo;
    res->highest_layer = hi;
    side_layers sl = {.max_layer = hi};
    cdem_status st = CDEM_OK;
    for (int k = 0; k < 2; k++) {
        sl.top[k] = malloc((size_t)(hi + 1) * sizeof(double));
        sl.bottom[k] = malloc((size_t)(hi + 1) * sizeof(double));
        if (!sl.top[k] || !sl.bottom[k])
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory measuring the fault's layers");
        for (int L = 0; L <= hi && st == CDEM_OK; L++) {
            sl.top[k][L] = -INFINITY;
            sl.bottom[k][L] = INFINITY;
        }
    }
    if (st == CDEM_OK)
        st = measure(s, z, seal_layers, n_seals, step, &sl, res, err);
    for (int k = 0; k < 2; k++) {
        free(sl.top[k]);
        free(sl.bottom[k]);
    }
    if (st != CDEM_OK)
        cdem_fault_seal_free(res);
    return st;
}
