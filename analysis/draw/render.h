/* render: draws one increment off-screen with cairo (PNG, PDF, SVG, or an RGBA buffer).
 *
 * Data-driven: the caller fills a cdem_render_scene (what to draw: the state, optional
 * per-element values, vectors, axes, the label) and cdem_render_options (how: colours,
 * toggles, layer banding, size, zoom); cdem_render_options_default gives the manual's
 * defaults. Elements are discs at their true radii in a y-up frame with equal x/y scale,
 * fitted into the plot area; the label sits above it, the scale bar below it and the
 * colour bar on its right (or, with colour_bar_space, the colour bar's room). See
 * docs/rendering.md for the colour rules and layout.
 * Ownership: nothing is kept; all inputs are borrowed for the duration of a call (the
 * caller keeps arrays alive). Scratch memory (O(n)) is allocated per call and freed.
 * Thread safety: no shared state; separate calls may run in parallel on separate surfaces.
 * Units: model coordinates, radii, displacements and axis lengths in m; angles in radians
 * counter-clockwise from +x; PNG/RGBA sizes in pixels, PDF/SVG sizes in points. */
#ifndef CDEM_RENDER_H
#define CDEM_RENDER_H

#include "cdem_error.h"
#include "colormap.h"
#include "outfile.h"
#include "state.h"

#include <cairo.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define CDEM_RENDER_MAX_SIZE 20000 /* largest width or height accepted, px or pt */

typedef enum {
    CDEM_RENDER_PNG = 0, /* raster, width x height pixels */
    CDEM_RENDER_PDF = 1, /* vector, width x height points */
    CDEM_RENDER_SVG = 2, /* vector, width x height points */
} cdem_render_format;

/* What to draw for one increment. Zero-initialise, then set what applies. */
typedef struct {
    const cdem_state *state; /* required; x, y, radius, layer, flags of n elements */

    const double *values;    /* optional, n values to colour elements by; NaN = undefined */
    double vmin, vmax;       /* colour limits of values, finite, vmin <= vmax */
    cdem_colormap_kind kind; /* magnitude (blue-green-red) or signed (blue-white-red) */
    const char *quantity;    /* colour bar title, e.g. "Total displacement"; NULL = none */
    const char *unit;        /* colour bar unit, e.g. "m"; NULL or "" = dimensionless */
    int above_tenth_max;     /* 1: colour only elements with |v| > 0.1 max(|vmin|,|vmax|);
                                the others keep their layer colours */

    const double *ux, *uy; /* optional, n displacements (m) drawn as vectors; NaN skips */
    double vector_scale;   /* exaggeration of vectors, > 0: 5 incremental, 1 total */

    const double *axis_x, *axis_y; /* optional, n_axes grid points (m) for axes */
    const double *axis_angle;      /* n_axes orientations (rad, ccw from +x); NaN skips */
    size_t n_axes;                 /* number of axis points, >= 0 */
    double axis_length;            /* m, full segment length; <= 0: 1.6 x largest radius */
    int axis_perpendicular;        /* 1: also draw the perpendicular set (second colour) */

    const char *label; /* optional text, e.g. "Increment 282   Net displacement 1127 m" */
} cdem_render_scene;

/* How to draw. Start from cdem_render_options_default. */
typedef struct {
    int width;  /* image width, px (PNG/RGBA) or pt (PDF/SVG), 16..CDEM_RENDER_MAX_SIZE */
    int height; /* image height, 16..CDEM_RENDER_MAX_SIZE, or 0 = from the view's aspect */

    int has_zoom;                /* 1: use the zoom box below; 0: fit all elements */
    double zoom_xmin, zoom_xmax; /* m, zoom box, xmin < xmax (when has_zoom) */
    double zoom_ymin, zoom_ymax; /* m, zoom box, ymin < ymax (when has_zoom) */
    double margin;               /* fit margin, fraction of the larger box side, 0..1 */

    int pregrowth_layers; /* number of pre-growth layers (layers 1..N), >= 0; default 24 */
    int band_layers;      /* layers per colour band in each sequence, >= 1; default 1 */
    int growth1_layers;   /* layers in growth sequence 1 (after the pre-growth), >= 0 */
    int highlight_first;  /* first layer of the highlighted range; 0 = no highlight */
    int highlight_last;   /* last highlighted layer, >= highlight_first */

    int show_fill;        /* 1: fill the discs; 0: outlines only */
    int show_outline;     /* 1: thin outline around every disc (always on when !show_fill) */
    int show_colours;     /* 1: colour by values when given; 0: layer colours only */
    int show_vectors;     /* 1: draw displacement vectors when given */
    int show_axes;        /* 1: draw axes when given */
    int show_scale_bar;   /* 1: draw the scale bar */
    int show_colour_bar;  /* 1: draw the colour bar (only when values are given) */
    int colour_bar_space; /* 1: keep the colour bar's room on the right (and its least plot
                             height) also when no colour bar is drawn, so that a picture
                             without one has the layout, hence the scale, of one with it */
    int show_label;       /* 1: draw the label (only when given) */

    double font_size;     /* text height, px or pt; <= 0: width / 70, at least 9 */
    double outline_width; /* outline line width, px or pt, > 0; default 0.5 */
    double line_width;    /* vector and axis line width, px or pt, > 0; default 1 */
    double weak_alpha;    /* opacity of weak-interval elements, 0..1; default 0.45 */

    cdem_rgba background;   /* image background (alpha 0 = transparent PNG) */
    cdem_rgba wall;         /* wall, fault and mylar elements: brown */
    cdem_rgba pregrowth[2]; /* alternating pre-growth bands: yellow, red */
    cdem_rgba growth1[2];   /* alternating growth sequence 1 bands: pale yellow, magenta */
    cdem_rgba growth2[2];   /* alternating growth sequence 2 bands: pale cyan, blue */
    cdem_rgba salt[2];      /* salt elements (salt.layer), alternating by pre-growth layer:
                               lilac, a darker lilac (a quantity's colours win, as for any
                               element) */
    cdem_rgba highlight;    /* highlighted layers */
    cdem_rgba biaxial_edge; /* biaxial edge elements: green */
    cdem_rgba footwall;     /* fixed footwall display elements: light grey */
    cdem_rgba undefined;    /* elements whose value is NaN: neutral grey */
    cdem_rgba outline;      /* disc outlines */
    cdem_rgba vector;       /* displacement vectors */
    cdem_rgba axis[2];      /* first and perpendicular axis sets */
    cdem_rgba text;         /* label, ticks, scale bar */
} cdem_render_options;

/* Where things land on the image (device units, origin top-left, y down). */
typedef struct {
    double width, height;          /* image size */
    double xmin, xmax, ymin, ymax; /* model view box, m */
    double scale;                  /* device units per m */
    double ox, oy;                 /* device position of model point (xmin, ymax) */
    double plot_x, plot_y;         /* plot area, top-left corner */
    double plot_w, plot_h;         /* plot area size */
    double bar_x, bar_y;           /* colour bar rectangle top-left (0 size when absent) */
    double bar_w, bar_h;           /* colour bar size; bottom = low end, top = high end */
    double font_size;              /* effective text height */
} cdem_render_layout;

/* Fills o with the defaults (1200 px wide, auto height, manual colours, all toggles on). */
void cdem_render_options_default(cdem_render_options *o);

/* Writes the effective options to f, one "key = value" line each (colours as
 * "#rrggbbaa", which cdem_render_parse_colour reads back); for --dry-run and file
 * attributes. */
void cdem_render_options_view(const cdem_render_options *o, FILE *f);

/* Formats c as "#rrggbbaa" into buf (at least 10 bytes). */
void cdem_render_format_colour(const cdem_rgba *c, char buf[10]);

/* Parses "#rrggbb" or "#rrggbbaa" (hex, case-insensitive) into *out. */
cdem_status cdem_render_parse_colour(const char *text, cdem_rgba *out, cdem_error *err);

/* Output format from the extension of path (.png, .pdf, .svg, case-insensitive). */
cdem_status cdem_render_format_from_path(const char *path, cdem_render_format *fmt,
                                         cdem_error *err);

/* A picture file being written: the cairo surface (an image for PNG; for PDF and SVG a
 * vector surface streaming into the temporary file) and the outfile it is committed to
 * (outfile.h: path.tmp renamed on success, removed on failure). */
typedef struct {
    cairo_surface_t *surf;  /* draw on this */
    cdem_outfile of;        /* the temporary file and its destination */
    cdem_render_format fmt; /* PNG, PDF or SVG */
    const char *path;       /* destination, for messages (caller's string) */
    const char *what;       /* command or module named in messages, e.g. "render" */
} cdem_render_target;

/* Starts writing a w x h picture to path. Fails with CDEM_ERR_IO naming the path when the
 * file cannot be created; nothing is left behind then. */
cdem_status cdem_render_target_open(cdem_render_target *t, const char *path, cdem_render_format fmt,
                                    int w, int h, const char *what, cdem_error *err);

/* Finishes the picture: when st is CDEM_OK writes it (PNG encoding or vector flush) and
 * renames it into place, otherwise discards it. Returns st, or the write error. */
cdem_status cdem_render_target_close(cdem_render_target *t, cdem_status st, cdem_error *err);

/* Bounding box of all elements (discs, finite ones only) grown by margin x the larger
 * side; a unit box around the origin when there are none. box = {xmin, xmax, ymin, ymax}.
 * Use it (or a union over increments) as the zoom box to keep animation frames still. */
void cdem_render_fit_box(const cdem_state *s, double margin, double box[4]);

/* Height (>= 16) an image of the given width gets when options->height is 0. */
cdem_status cdem_render_auto_height(const cdem_render_scene *sc, const cdem_render_options *o,
                                    int *height, cdem_error *err);

/* Validates the inputs and computes the layout for a width x height image. */
cdem_status cdem_render_layout_compute(const cdem_render_scene *sc, const cdem_render_options *o,
                                       double width, double height, cdem_render_layout *lay,
                                       cdem_error *err);

/* Device position of model point (x, y). */
void cdem_render_layout_to_device(const cdem_render_layout *lay, double x, double y, double *dx,
                                  double *dy);

/* Draws the scene on cr over a width x height device area (any cairo surface). */
cdem_status cdem_render_draw(cairo_t *cr, double width, double height, const cdem_render_scene *sc,
                             const cdem_render_options *o, cdem_error *err);

/* Draws onto a caller-provided cairo image surface (ARGB32 or RGB24), using its size;
 * o->width/height are ignored. */
cdem_status cdem_render_to_surface(cairo_surface_t *surface, const cdem_render_scene *sc,
                                   const cdem_render_options *o, cdem_error *err);

/* Draws into rgba (width x height x 4 bytes, row-major from the top, R,G,B,A bytes, not
 * premultiplied), e.g. a GIF frame. o->width/height are ignored. */
cdem_status cdem_render_to_rgba(uint8_t *rgba, int width, int height, const cdem_render_scene *sc,
                                const cdem_render_options *o, cdem_error *err);

/* Writes the scene to path; the format follows the extension (.png, .pdf, .svg). */
cdem_status cdem_render_to_file(const char *path, const cdem_render_scene *sc,
                                const cdem_render_options *o, cdem_error *err);

#endif
