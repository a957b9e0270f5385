/* plot: a small cairo line-plot module for calibration and evolution figures.
 *
 * A figure is one or more panels side by side; a panel (cdem_plot) has a title, axis
 * labels, axes with "nice" ticks (1, 2, 5 x 10^k) and several series drawn as lines
 * and/or markers, with a legend in the corner of the plot area that covers the fewest of
 * the drawn points (top right when several are free; cdem_plot_legend_box). Series without
 * a colour of their own differ by colour and, past the palette's ten colours, by dash
 * pattern (cdem_plot_series_style). Axis ranges come
 * from the data (extended to whole ticks) unless fixed; equal_aspect makes one unit of x as
 * long as one unit of y (Mohr circles). The margins around the plot area depend only on
 * the font size, never on the text, so cdem_plot_layout_compute tells exactly where a data
 * point lands. Output format follows the file extension (.png, .pdf, .svg).
 * Ownership: nothing is kept; arrays are borrowed for the duration of a call.
 * Thread safety: no shared state. Units: data in the caller's units; sizes in px (PNG) or
 * pt (PDF/SVG). */
#ifndef CDEM_PLOT_H
#define CDEM_PLOT_H

#include "cdem_error.h"
#include "colormap.h"

#include <cairo.h>
#include <stddef.h>

/* One line of a panel. Non-finite points break the line (and draw no marker). */
typedef struct {
    const double *x;   /* n abscissae, any finite values */
    const double *y;   /* n ordinates, any finite values */
    size_t n;          /* number of points, >= 0 */
    const char *label; /* legend text; NULL or "" = not in the legend */
    cdem_rgba colour;  /* line and marker colour; alpha 0 = next colour of the palette */
    int line;          /* 1: join the points with a line */
    int markers;       /* 1: draw a small disc at every point */
    int dashed;        /* 1: dashed line */
    const char *tag;   /* text written in the line's colour above its highest point (a Mohr
                          circle's confining pressure); NULL or "" = none. A tag that would
                          cover an earlier one is left out. */
} cdem_plot_series;

/* One panel. Zero-initialise, then set what applies. */
typedef struct {
    const char *title;              /* above the plot area; NULL = none */
    const char *xlabel, *ylabel;    /* axis labels; NULL = none */
    const cdem_plot_series *series; /* n_series series */
    size_t n_series;                /* >= 0 */
    int fix_x, fix_y;               /* 1: use the range below instead of the data's */
    double xmin, xmax;              /* fixed x range, xmin < xmax (when fix_x) */
    double ymin, ymax;              /* fixed y range, ymin < ymax (when fix_y) */
    int equal_aspect;               /* 1: same device length per unit on x and y */
    int no_legend;                  /* 1: no legend even when series have labels */
} cdem_plot;

/* Where a panel lands (device units, origin top-left, y down). */
typedef struct {
    double xmin, xmax, ymin, ymax; /* data range shown */
    double plot_x, plot_y;         /* plot area top-left corner */
    double plot_w, plot_h;         /* plot area size, > 0 */
    double xtick0, xstep;          /* first x tick and tick spacing */
    double ytick0, ystep;          /* first y tick and tick spacing */
    double font_size;              /* text height */
} cdem_plot_layout;

/* Tick spacing 1, 2 or 5 x 10^k giving about `target` (>= 2) intervals over [lo, hi]
 * (lo < hi, finite); *first = the first multiple of the step >= lo. */
void cdem_plot_nice_ticks(double lo, double hi, int target, double *first, double *step);

/* Layout of panel p drawn in the device box (x, y, w, h). Fails on bad series arrays,
 * a bad fixed range or a box too small to hold the margins. */
cdem_status cdem_plot_layout_compute(const cdem_plot *p, double x, double y, double w, double h,
                                     cdem_plot_layout *lay, cdem_error *err);

/* Device position of data point (x, y). */
void cdem_plot_to_device(const cdem_plot_layout *lay, double x, double y, double *dx, double *dy);

/* Draws panel p into the device box (x, y, w, h) of cr; *lay (may be NULL) gets its layout.
 * The background is not painted. */
cdem_status cdem_plot_draw(cairo_t *cr, const cdem_plot *p, double x, double y, double w, double h,
                           cdem_plot_layout *lay, cdem_error *err);

/* Writes n_panels panels side by side on a white width x height image (16..20000 each) to
 * path (.png, .pdf, .svg). */
cdem_status cdem_plot_to_file(const char *path, const cdem_plot *panels, size_t n_panels, int width,
                              int height, cdem_error *err);

/* Colours in the plot palette. */
#define CDEM_PLOT_PALETTE_N 10

/* The i-th colour of the plot palette (cycles after CDEM_PLOT_PALETTE_N). */
cdem_rgba cdem_plot_palette(size_t i);

/* Line dash patterns of the series. */
typedef enum { CDEM_PLOT_SOLID = 0, CDEM_PLOT_DASHED = 1, CDEM_PLOT_DOTTED = 2 } cdem_plot_dash;

/* How series s, the i-th of its panel, is drawn: its own colour when it has one (alpha >
 * 0), else the palette's i-th; dashed when s->dashed, else, for a palette colour, solid for
 * the first CDEM_PLOT_PALETTE_N series, dashed for the next ten and dotted for the ten after
 * (so 30 series without colours of their own all differ), then again. */
void cdem_plot_series_style(const cdem_plot_series *s, size_t i, cdem_rgba *colour,
                            cdem_plot_dash *dash);

/* The legend box of panel p in layout lay (device x, y, w, h in box): the corner of the plot
 * area (top right, top left, bottom right, bottom left: the first of those with the fewest)
 * whose box covers the fewest of the points drawn (every data point and every 2 px along the
 * lines) and of the tags. Returns 0 (box untouched) when the panel has no legend. */
int cdem_plot_legend_box(const cdem_plot *p, const cdem_plot_layout *lay, double box[4]);

/* How many of the points drawn in panel p (every data point and every 2 px along its lines)
 * fall inside the device box (x, y, w, h). */
size_t cdem_plot_points_in_box(const cdem_plot *p, const cdem_plot_layout *lay,
                               const double box[4]);

#endif
