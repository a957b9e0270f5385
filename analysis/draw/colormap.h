/* colormap: the colour scales used to colour elements by a value, and RGBA colours.
 *
 * Two scales, after the original program: "magnitude" (blue - cyan - green - yellow - red,
 * blue = low, red = high; five stops, linear between them) for displacements, strains and
 * stresses, and "signed" (blue - white - red, white at zero) for uplift-subsidence, dilation
 * and rotation. The signed scale eases into its end colours (sin-shaped ramp from white,
 * zero slope at the ends) as the manual v4.8 asks ("smoother gradients towards the end
 * values"). Signed limits are made symmetric, [-M, M] with M = max(|vmin|, |vmax|), so
 * zero is always white.
 * Ownership: plain values, no allocation. Thread safety: pure functions.
 * Units: colour channels 0..1 (not premultiplied); t is the position on the scale, 0..1. */
#ifndef CDEM_COLORMAP_H
#define CDEM_COLORMAP_H

#include "cdem_error.h"

typedef struct {
    double r; /* red, 0..1 */
    double g; /* green, 0..1 */
    double b; /* blue, 0..1 */
    double a; /* opacity, 0 (transparent) .. 1 (opaque) */
} cdem_rgba;

typedef enum {
    CDEM_COLORMAP_MAGNITUDE = 0, /* blue-green-red, for values of one sign */
    CDEM_COLORMAP_SIGNED = 1,    /* blue-white-red, white at zero */
} cdem_colormap_kind;

/* Colour at position t of the scale (t clamped to 0..1, NaN gives t = 0.5); alpha 1. */
cdem_rgba cdem_colormap_eval(cdem_colormap_kind kind, double t);

/* Effective limits of the scale for data limits vmin <= vmax: unchanged for magnitude,
 * symmetric [-M, M] for signed. */
void cdem_colormap_limits(cdem_colormap_kind kind, double vmin, double vmax, double *lo,
                          double *hi);

/* Position 0..1 of value v on the scale with data limits vmin..vmax (clamped). A zero-width
 * range maps every value to 0 (magnitude) or 0.5 (signed). NaN v gives NaN. */
double cdem_colormap_position(cdem_colormap_kind kind, double v, double vmin, double vmax);

/* Labels of the colour bar's n >= 2 evenly spaced ticks from lo to hi (lo <= hi, finite):
 * with the fewest significant digits, 4 to 17, that make every two neighbouring labels
 * differ (issue 46: "%.4g" labelled a range of 1000.0001..1000.0005 m "1000" five times); a
 * value within 1e-12 of the range of 0 is "0". lo == hi gives the one value n times. */
#define CDEM_COLORMAP_TICK_CHARS 32
void cdem_colormap_tick_labels(double lo, double hi, int n,
                               char (*labels)[CDEM_COLORMAP_TICK_CHARS]);

/* Parses "magnitude" / "bgr" or "signed" / "bwr" (CDEM_ERR_RANGE lists the valid names). */
cdem_status cdem_colormap_parse(const char *name, cdem_colormap_kind *kind, cdem_error *err);

/* Name of a kind ("magnitude", "signed"). */
const char *cdem_colormap_name(cdem_colormap_kind kind);

#endif
