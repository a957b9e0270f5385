/* surface: see surface.h. */
#include "surface.h"

#include <math.h>
#include <stdint.h>

int cdem_surface_is_free(const cdem_state *s, size_t i) {
    return !(s->flags[i] & CDEM_FLAGS_BOUNDARY) && isfinite(s->x[i]) && isfinite(s->y[i]) &&
           isfinite(s->radius[i]) && s->radius[i] > 0;
}

void cdem_surface_column_tops(const cdem_state *s, double x0, double w, size_t ncol, double x_lo,
                              double x_hi, size_t *top) {
    for (size_t c = 0; c < ncol; c++)
        top[c] = SIZE_MAX;
    if (!(w > 0))
        return;
    for (size_t i = 0; i < s->n; i++) {
        if (!cdem_surface_is_free(s, i) || !(s->x[i] >= x_lo && s->x[i] < x_hi))
            continue;
        const double fc = floor((s->x[i] - x0) / w);
        if (!(fc >= 0) || fc >= (double)ncol)
            continue;
        const size_t c = (size_t)fc;
        if (top[c] == SIZE_MAX || s->y[i] + s->radius[i] > s->y[top[c]] + s->radius[top[c]])
            top[c] = i;
    }
}
