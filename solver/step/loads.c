/* loads: see loads.h. */
#include "loads.h"

#include "bc.h"
#include "grid.h"
#include "surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cdem_loads_init(cdem_loads *l, double gravity, double tilt_deg, double max_radius) {
    memset(l, 0, sizeof *l);
    l->gravity = gravity;
    cdem_model_gravity_vector(gravity, tilt_deg, &l->gravity_x, &l->gravity_y);
    l->model_gx = l->gravity_x;
    l->model_gy = l->gravity_y;
    l->column_width = 2.0 * max_radius;
}

void cdem_loads_set_gravity(cdem_loads *l, double gx, double gy) {
    l->gravity_x = gx;
    l->gravity_y = gy;
}

void cdem_loads_free(cdem_loads *l) {
    if (!l)
        return;
    free(l->col_top);
    free(l->band_lo);
    free(l->band_hi);
    memset(l, 0, sizeof *l);
}

cdem_status cdem_loads_set_overburden(cdem_loads *l, double pressure, cdem_error *err) {
    if (!isfinite(pressure) || pressure < 0.0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: surface.overburden_pressure = %g N/m: must be a finite "
                         "number >= 0",
                         pressure);
    l->overburden_force = pressure * l->column_width;
    return CDEM_OK;
}

cdem_status cdem_loads_set_confining(cdem_loads *l, double pressure, long equil_steps, long step,
                                     cdem_error *err) {
    if (!isfinite(pressure) || pressure < 0.0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: boundary.confining_pressure = %g N/m: must be a finite "
                         "number >= 0",
                         pressure);
    l->confining_pressure = pressure;
    l->confining_equil = equil_steps;
    l->confining_factor = cdem_bc_confining_ramp(step, equil_steps);
    return CDEM_OK;
}

cdem_status cdem_loads_find_edges(cdem_loads *l, cdem_state *s, cdem_error *err) {
    double ymin = INFINITY, ymax = -INFINITY, xmin = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~(uint32_t)CDEM_FLAG_BIAXIAL_EDGE;
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        ymin = fmin(ymin, s->y[i]);
        ymax = fmax(ymax, s->y[i]);
        xmin = fmin(xmin, s->x[i]);
        xmax = fmax(xmax, s->x[i]);
    }
    l->n_edge = 0;
    if (!isfinite(ymin) || !(l->column_width > 0.0))
        return CDEM_OK;
    l->edge_x_mid = 0.5 * (xmin + xmax);
    const double w = l->column_width;
    const double span = (ymax - ymin) / w;
    if (!(span < 1e8))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: free elements span %g m = %g bands of %g m: too many for "
                         "the edge search",
                         ymax - ymin, span, w);
    const size_t nb = (size_t)span + 1;
    if (nb > l->bandcap) {
        const size_t c = nb + nb / 2 + 16;
        int32_t *lo = realloc(l->band_lo, c * sizeof *lo);
        if (lo)
            l->band_lo = lo;
        int32_t *hi = lo ? realloc(l->band_hi, c * sizeof *hi) : NULL;
        if (!lo || !hi)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu bands)", c);
        l->band_hi = hi;
        l->bandcap = c;
    }
    for (size_t b = 0; b < nb; b++)
        l->band_lo[b] = l->band_hi[b] = -1;
    const cdem_grid bands = {.x0 = 0.0, .y0 = ymin, .cell = w, .nx = 1, .ny = nb};
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        const size_t b = cdem_grid_row(&bands, s->y[i]);
        const int32_t lo = l->band_lo[b], hi = l->band_hi[b];
        if (lo < 0 || s->x[i] < s->x[lo])
            l->band_lo[b] = (int32_t)i;
        if (hi < 0 || s->x[i] > s->x[hi])
            l->band_hi[b] = (int32_t)i;
    }
    long count = 0;
    for (size_t b = 0; b < nb; b++) {
        const int32_t e[2] = {l->band_lo[b], l->band_hi[b]};
        for (int k = 0; k < 2; k++) {
            if (e[k] < 0 || (s->flags[e[k]] & CDEM_FLAG_BIAXIAL_EDGE))
                continue;
            s->flags[e[k]] |= CDEM_FLAG_BIAXIAL_EDGE;
            count++;
        }
    }
    l->n_edge = count;
    return CDEM_OK;
}

cdem_status cdem_loads_find_surface(cdem_loads *l, cdem_state *s, cdem_error *err) {
    double xmin = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~(uint32_t)CDEM_FLAG_SURFACE;
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        xmin = fmin(xmin, s->x[i]);
        xmax = fmax(xmax, s->x[i]);
    }
    l->n_surface = 0;
    if (!isfinite(xmin) || !(l->column_width > 0.0))
        return CDEM_OK;
    const double w = l->column_width;
    const double span = (xmax - xmin) / w;
    if (!(span < 1e8))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "integrator: free elements span %g m = %g columns of %g m: too many "
                         "for the surface search",
                         xmax - xmin, span, w);
    const size_t ncol = (size_t)span + 1;
    if (ncol > l->colcap) {
        size_t c = ncol + ncol / 2 + 16;
        size_t *q = realloc(l->col_top, c * sizeof *q);
        if (!q)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu columns)", c);
        l->col_top = q;
        l->colcap = c;
    }
    const cdem_grid cols = {.x0 = xmin, .y0 = 0.0, .cell = w, .nx = ncol, .ny = 1};
    cdem_surface_columns(s, &cols, CDEM_SURFACE_BY_CENTRE, -INFINITY, INFINITY, l->col_top);
    long count = 0;
    for (size_t c = 0; c < ncol; c++) {
        if (l->col_top[c] == SIZE_MAX)
            continue;
        s->flags[l->col_top[c]] |= CDEM_FLAG_SURFACE;
        count++;
    }
    l->n_surface = count;
    return CDEM_OK;
}

void cdem_loads_begin_step(cdem_loads *l, long step) {
    if (l->confining_pressure > 0.0)
        l->confining_factor = cdem_bc_confining_ramp(step, l->confining_equil);
}

cdem_status cdem_loads_after_build(cdem_loads *l, cdem_state *s, cdem_error *err) {
    if (l->overburden_force > 0.0)
        CDEM_TRY(cdem_loads_find_surface(l, s, err));
    if (l->confining_pressure > 0.0)
        CDEM_TRY(cdem_loads_find_edges(l, s, err));
    return CDEM_OK;
}

cdem_force_loads cdem_loads_of_step(const cdem_loads *l) {
    const cdem_force_loads f = {
        .gravity_x = l->gravity_x,
        .gravity_y = l->gravity_y,
        .surface_force = l->overburden_force,
        .edge_force = l->confining_pressure * l->column_width * l->confining_factor,
        .edge_x_mid = l->edge_x_mid,
    };
    return f;
}
