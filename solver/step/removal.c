/* removal: see removal.h. */
#include "removal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cdem_removal_init(cdem_removal *r, double max_radius) {
    memset(r, 0, sizeof *r);
    r->max_radius = max_radius;
}

void cdem_removal_free(cdem_removal *r) {
    if (!r)
        return;
    free(r->keep);
    free(r->removed_ids);
    memset(r, 0, sizeof *r);
}

static int is_free(uint32_t flags) {
    return !(flags & CDEM_FLAGS_BOUNDARY);
}

cdem_status cdem_removal_reserve(cdem_removal *r, size_t n, cdem_error *err) {
    if (n <= r->keepcap)
        return CDEM_OK;
    size_t c = n + n / 2 + 16;
    unsigned char *k = realloc(r->keep, c);
    if (!k)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu elements)", c);
    r->keep = k;
    r->keepcap = c;
    return CDEM_OK;
}

cdem_status cdem_removal_collect(cdem_removal *r, const cdem_state *s, size_t nrem,
                                 cdem_error *err) {
    if (nrem > r->removed_cap) {
        size_t c = nrem + r->removed_cap + 16;
        int32_t *q = realloc(r->removed_ids, c * sizeof *q);
        if (!q)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu ids)", c);
        r->removed_ids = q;
        r->removed_cap = c;
    }
    size_t k = 0;
    for (size_t i = 0; i < s->n && k < nrem; i++)
        if (!r->keep[i])
            r->removed_ids[k++] = s->id[i];
    return CDEM_OK;
}

cdem_status cdem_removal_find_escapes(cdem_removal *r, const cdem_state *s, size_t *count,
                                      cdem_error *err) {
    *count = 0;
    if (!r->bounds_set)
        return CDEM_OK;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_WALL))
            continue;
        /* plain comparisons, not the fmin/fmax library calls (this runs at every build) */
        const double xi = s->x[i], yi = s->y[i];
        xmin = xi < xmin ? xi : xmin;
        xmax = xi > xmax ? xi : xmax;
        ymin = yi < ymin ? yi : ymin;
    }
    if (!isfinite(xmin))
        return CDEM_OK; /* no walls: nothing to escape from */
    r->escape_xmin = xmin;
    r->escape_xmax = xmax;
    r->escape_ymin = ymin;
    CDEM_TRY(cdem_removal_reserve(r, s->n, err));
    size_t nrem = 0;
    for (size_t i = 0; i < s->n; i++) {
        int out = 0;
        if (is_free(s->flags[i])) {
            const double rad = s->radius[i];
            out = s->x[i] < xmin - rad || s->x[i] > xmax + rad || s->y[i] < ymin - r->max_radius;
        }
        r->keep[i] = (unsigned char)!out;
        nrem += (size_t)out;
    }
    *count = nrem;
    return cdem_removal_collect(r, s, nrem, err);
}

cdem_status cdem_removal_mark_above(cdem_removal *r, const cdem_state *s, double ymax,
                                    size_t *count, cdem_error *err) {
    *count = 0;
    CDEM_TRY(cdem_removal_reserve(r, s->n, err));
    size_t nrem = 0;
    for (size_t i = 0; i < s->n; i++) {
        const int out = !(s->flags[i] & CDEM_FLAGS_BOUNDARY) && s->y[i] > ymax;
        r->keep[i] = (unsigned char)!out;
        nrem += (size_t)out;
    }
    *count = nrem;
    return CDEM_OK;
}

cdem_status cdem_removal_mark_by_mode(cdem_removal *r, cdem_state *s, cdem_bc *bc, size_t *count,
                                      cdem_error *err) {
    *count = 0;
    CDEM_TRY(cdem_removal_reserve(r, s->n, err));
    memset(r->keep, 1, s->n);
    size_t nrem = 0;
    CDEM_TRY(cdem_bc_begin_deformation(bc, s, r->keep, &nrem, err));
    if (nrem == 0)
        return CDEM_OK;
    size_t check = 0;
    for (size_t i = 0; i < s->n; i++)
        check += r->keep[i] == 0;
    if (check != nrem)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "boundary mode %s: begin_deformation reported %zu elements to remove "
                         "but marked %zu",
                         bc->name, nrem, check);
    *count = nrem;
    return CDEM_OK;
}
