/* surface: see surface.h. */
#include "surface.h"

#include <math.h>
#include <stdint.h>

int cdem_surface_is_free(const cdem_state *s, size_t i) {
    return !(s->flags[i] & CDEM_FLAGS_BOUNDARY) && isfinite(s->x[i]) && isfinite(s->y[i]) &&
           isfinite(s->radius[i]) && s->radius[i] > 0;
}

/* The height by which element i competes for its column. */
static double height_of(const cdem_state *s, size_t i, cdem_surface_height by) {
    return by == CDEM_SURFACE_BY_TOP ? s->y[i] + s->radius[i] : s->y[i];
}

void cdem_surface_columns(const cdem_state *s, const cdem_grid *cols, cdem_surface_height by,
                          double x_lo, double x_hi, size_t *top) {
    for (size_t c = 0; c < cols->nx; c++)
        top[c] = SIZE_MAX;
    if (!(cols->cell > 0))
        return;
    for (size_t i = 0; i < s->n; i++) {
        size_t c = 0;
        if (!cdem_surface_is_free(s, i) || !(s->x[i] >= x_lo && s->x[i] < x_hi) ||
            !cdem_grid_col_inside(cols, s->x[i], &c))
            continue;
        if (top[c] == SIZE_MAX || height_of(s, i, by) > height_of(s, top[c], by))
            top[c] = i;
    }
}

void cdem_surface_column_tops(const cdem_state *s, double x0, double w, size_t ncol, double x_lo,
                              double x_hi, size_t *top) {
    const cdem_grid cols = {.x0 = x0, .y0 = 0.0, .cell = w, .nx = ncol, .ny = 1};
    cdem_surface_columns(s, &cols, CDEM_SURFACE_BY_TOP, x_lo, x_hi, top);
}

double cdem_surface_top(const cdem_state *s) {
    double top = -INFINITY;
    for (size_t i = 0; i < s->n; i++)
        if (cdem_surface_is_free(s, i))
            top = fmax(top, s->y[i] + s->radius[i]);
    return top;
}
