/* colormap: see colormap.h. The magnitude scale is piecewise linear through five stops of
 * full saturation (a "jet"-like ramp), so hue falls monotonically from 240 deg (blue)
 * to 0 deg (red) and no stop is darker than its neighbours. The signed scale mixes white
 * with the end colour by sin(pi/2 u), u = distance from the centre (0..1). */
#include "colormap.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct {
    double t;       /* position of the stop, 0..1, ascending */
    double r, g, b; /* colour at the stop, 0..1 */
} colormap_stop;

static const colormap_stop magnitude_stops[] = {
    {0.00, 0.0, 0.0, 1.0}, /* blue: low */
    {0.25, 0.0, 1.0, 1.0}, /* cyan */
    {0.50, 0.0, 1.0, 0.0}, /* green */
    {0.75, 1.0, 1.0, 0.0}, /* yellow */
    {1.00, 1.0, 0.0, 0.0}, /* red: high */
};

static const cdem_rgba signed_low = {0.0, 0.0, 1.0, 1.0};  /* blue: most negative */
static const cdem_rgba signed_high = {1.0, 0.0, 0.0, 1.0}; /* red: most positive */

static const double colormap_pi = 3.14159265358979323846;

cdem_rgba cdem_colormap_eval(cdem_colormap_kind kind, double t) {
    if (isnan(t))
        t = 0.5;
    if (t < 0.0)
        t = 0.0;
    if (t > 1.0)
        t = 1.0;
    cdem_rgba c = {1.0, 1.0, 1.0, 1.0};
    if (kind == CDEM_COLORMAP_SIGNED) {
        const cdem_rgba *end = t < 0.5 ? &signed_low : &signed_high;
        double u = fabs(t - 0.5) * 2.0;
        double w = sin(0.5 * colormap_pi * u);
        c.r = 1.0 + (end->r - 1.0) * w;
        c.g = 1.0 + (end->g - 1.0) * w;
        c.b = 1.0 + (end->b - 1.0) * w;
        return c;
    }
    const size_t n = sizeof magnitude_stops / sizeof magnitude_stops[0];
    size_t k = 0;
    while (k + 2 < n && t > magnitude_stops[k + 1].t)
        k++;
    const colormap_stop *a = &magnitude_stops[k], *b = &magnitude_stops[k + 1];
    double f = (t - a->t) / (b->t - a->t);
    c.r = a->r + (b->r - a->r) * f;
    c.g = a->g + (b->g - a->g) * f;
    c.b = a->b + (b->b - a->b) * f;
    return c;
}

void cdem_colormap_limits(cdem_colormap_kind kind, double vmin, double vmax, double *lo,
                          double *hi) {
    if (kind == CDEM_COLORMAP_SIGNED) {
        double m = fmax(fabs(vmin), fabs(vmax));
        *lo = -m;
        *hi = m;
    } else {
        *lo = vmin;
        *hi = vmax;
    }
}

double cdem_colormap_position(cdem_colormap_kind kind, double v, double vmin, double vmax) {
    if (isnan(v))
        return NAN;
    double lo, hi;
    cdem_colormap_limits(kind, vmin, vmax, &lo, &hi);
    if (!(hi > lo))
        return kind == CDEM_COLORMAP_SIGNED ? 0.5 : 0.0;
    double t = (v - lo) / (hi - lo);
    if (t < 0.0)
        t = 0.0;
    if (t > 1.0)
        t = 1.0;
    return t;
}

cdem_status cdem_colormap_parse(const char *name, cdem_colormap_kind *kind, cdem_error *err) {
    if (name && (strcmp(name, "magnitude") == 0 || strcmp(name, "bgr") == 0)) {
        *kind = CDEM_COLORMAP_MAGNITUDE;
        return CDEM_OK;
    }
    if (name && (strcmp(name, "signed") == 0 || strcmp(name, "bwr") == 0)) {
        *kind = CDEM_COLORMAP_SIGNED;
        return CDEM_OK;
    }
    return CDEM_FAIL(err, CDEM_ERR_RANGE,
                     "colour scale '%s' is unknown: valid names are 'magnitude' (or 'bgr', "
                     "blue-green-red) and 'signed' (or 'bwr', blue-white-red)",
                     name ? name : "(null)");
}

const char *cdem_colormap_name(cdem_colormap_kind kind) {
    return kind == CDEM_COLORMAP_SIGNED ? "signed" : "magnitude";
}

void cdem_colormap_tick_labels(double lo, double hi, int n,
                               char (*labels)[CDEM_COLORMAP_TICK_CHARS]) {
    if (n < 1)
        return;
    for (int digits = 4; digits <= 17; digits++) {
        for (int k = 0; k < n; k++) {
            double v = n > 1 ? lo + (double)k / (n - 1) * (hi - lo) : lo;
            if (fabs(v) < 1e-12 * fmax(fabs(lo), fabs(hi)))
                v = 0.0;
            snprintf(labels[k], CDEM_COLORMAP_TICK_CHARS, "%.*g", digits, v);
        }
        int distinct = 1;
        for (int k = 1; k < n && distinct; k++)
            distinct = strcmp(labels[k], labels[k - 1]) != 0;
        if (distinct || !(hi > lo))
            return;
    }
}
