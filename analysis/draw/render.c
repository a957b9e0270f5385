/* render: see render.h.
 *
 * Speed: drawing 50,000 discs one cairo_fill at a time costs one rasterisation pass per
 * disc. Instead every element is given a colour slot (fixed layer/flag colours, or one of
 * 257 bins of the colour map, each in an opaque and a weak/semi-transparent variant), the
 * elements are bucket-sorted by slot, and each slot is filled as one multi-disc path. The
 * 257-bin quantisation of values is below what the eye (and the 8-bit output) resolves.
 * All outlines are stroked as one path. Elements wholly outside the view box are culled
 * (this also keeps cairo's fixed-point device coordinates in range when zoomed in).
 * Draw order: fills by slot, outlines, vectors, axes, then label, scale bar, colour bar. */
#include "render.h"

#include "outfile.h"
#include "raster.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    SLOT_WALL = 0,  /* wall, fault, mylar */
    SLOT_FOOTWALL,  /* fixed footwall display elements */
    SLOT_EDGE,      /* biaxial edge elements */
    SLOT_UNDEFINED, /* NaN value */
    SLOT_HIGHLIGHT, /* highlighted layer range */
    SLOT_PRE0,      /* pre-growth band colours 0, 1 */
    SLOT_PRE1,      /* */
    SLOT_G1_0,      /* growth sequence 1 band colours 0, 1 */
    SLOT_G1_1,      /* */
    SLOT_G2_0,      /* growth sequence 2 band colours 0, 1 */
    SLOT_G2_1,      /* */
    SLOT_SALT0,     /* salt band colours 0, 1 */
    SLOT_SALT1,     /* */
    SLOT_MAP,       /* first of the colour-map bins */
    MAP_BINS = 257, /* colour-map bins, odd so that t = 0.5 (white, green) is a bin */
    SLOT_FIXED_N = SLOT_MAP + MAP_BINS, /* slots of one opacity variant */
    SLOT_N = 2 * SLOT_FIXED_N,          /* opaque slots, then weak (semi-transparent) ones */
};

static const double render_pi = 3.14159265358979323846;

static int disc_ok(const cdem_state *s, size_t i) {
    return isfinite(s->x[i]) && isfinite(s->y[i]) && isfinite(s->radius[i]) && s->radius[i] > 0.0;
}

void cdem_render_fit_box(const cdem_state *s, double margin, double box[4]) {
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    if (s && s->x && s->y && s->radius) {
        for (size_t i = 0; i < s->n; i++) {
            if (!disc_ok(s, i))
                continue;
            double r = s->radius[i];
            x0 = fmin(x0, s->x[i] - r);
            x1 = fmax(x1, s->x[i] + r);
            y0 = fmin(y0, s->y[i] - r);
            y1 = fmax(y1, s->y[i] + r);
        }
    }
    if (!(x1 > x0) || !(y1 > y0)) {
        double cx = x1 >= x0 ? 0.5 * (x0 + x1) : 0.0, cy = y1 >= y0 ? 0.5 * (y0 + y1) : 0.0;
        x0 = cx - 0.5;
        x1 = cx + 0.5;
        y0 = cy - 0.5;
        y1 = cy + 0.5;
    }
    if (!(margin >= 0.0) || !isfinite(margin))
        margin = 0.0;
    double m = margin * fmax(x1 - x0, y1 - y0);
    box[0] = x0 - m;
    box[1] = x1 + m;
    box[2] = y0 - m;
    box[3] = y1 + m;
}

static int colour_ok(const cdem_rgba *c) {
    return c->r >= 0 && c->r <= 1 && c->g >= 0 && c->g <= 1 && c->b >= 0 && c->b <= 1 &&
           c->a >= 0 && c->a <= 1;
}

static int has_values(const cdem_render_scene *sc, const cdem_render_options *o) {
    return sc->values && o->show_colours;
}

static int has_colour_bar(const cdem_render_scene *sc, const cdem_render_options *o) {
    return has_values(sc, o) && o->show_colour_bar;
}

/* The layout makes room for a colour bar: one is drawn, or its room is kept empty
 * (colour_bar_space: pictures with and without one then share the plot area). */
static int colour_bar_room(const cdem_render_scene *sc, const cdem_render_options *o) {
    return has_colour_bar(sc, o) || o->colour_bar_space;
}

/* Checks everything the drawing relies on, so bad input fails with a message. */
static cdem_status validate(const cdem_render_scene *sc, const cdem_render_options *o,
                            cdem_error *err) {
    if (!sc || !o || !sc->state)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "render: scene, options and scene.state must "
                         "not be NULL");
    const cdem_state *s = sc->state;
    if (s->n > 0 && (!s->x || !s->y || !s->radius))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "render: state has %zu elements but no x, y or radius array", s->n);
    if (s->n > (size_t)UINT32_MAX)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "render: %zu elements exceed the limit of %u", s->n,
                         UINT32_MAX);
    if (sc->values && !(isfinite(sc->vmin) && isfinite(sc->vmax) && sc->vmin <= sc->vmax))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: colour limits vmin = %g, vmax = %g: must be finite with "
                         "vmin <= vmax",
                         sc->vmin, sc->vmax);
    if (sc->values && sc->kind != CDEM_COLORMAP_MAGNITUDE && sc->kind != CDEM_COLORMAP_SIGNED)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: colour scale kind = %d: must be %d "
                         "(magnitude) or %d (signed)",
                         (int)sc->kind, CDEM_COLORMAP_MAGNITUDE, CDEM_COLORMAP_SIGNED);
    if ((sc->ux != NULL) != (sc->uy != NULL))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "render: vectors need both ux and uy (got only %s)",
                         sc->ux ? "ux" : "uy");
    if (sc->ux && o->show_vectors && !(isfinite(sc->vector_scale) && sc->vector_scale > 0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: vector exaggeration = %g: must be finite and > 0 (5 for "
                         "incremental, 1 for total displacement)",
                         sc->vector_scale);
    if (sc->n_axes > 0 && (!sc->axis_x || !sc->axis_y || !sc->axis_angle))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "render: %zu axes but axis_x, axis_y or axis_angle is NULL", sc->n_axes);
    if (!isfinite(sc->axis_length))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "render: axis length = %g m: must be finite",
                         sc->axis_length);
    if (o->has_zoom &&
        !(isfinite(o->zoom_xmin) && isfinite(o->zoom_xmax) && isfinite(o->zoom_ymin) &&
          isfinite(o->zoom_ymax) && o->zoom_xmin < o->zoom_xmax && o->zoom_ymin < o->zoom_ymax))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: zoom box x %g..%g, y %g..%g m: must be finite with "
                         "xmin < xmax and ymin < ymax",
                         o->zoom_xmin, o->zoom_xmax, o->zoom_ymin, o->zoom_ymax);
    if (!(o->margin >= 0.0 && o->margin <= 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "render: margin = %g: must be in 0..1", o->margin);
    if (o->pregrowth_layers < 0 || o->growth1_layers < 0 || o->band_layers < 1)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: pregrowth_layers = %d, growth1_layers = %d, band_layers = %d: "
                         "layer counts must be >= 0 and band_layers >= 1",
                         o->pregrowth_layers, o->growth1_layers, o->band_layers);
    if (o->highlight_first < 0 ||
        (o->highlight_first > 0 && o->highlight_last < o->highlight_first))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: highlighted layers %d..%d: need 0 (none) or "
                         "1 <= first <= last",
                         o->highlight_first, o->highlight_last);
    if (!(o->weak_alpha >= 0.0 && o->weak_alpha <= 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "render: weak_alpha = %g: must be in 0..1",
                         o->weak_alpha);
    if (!(isfinite(o->outline_width) && o->outline_width > 0 && isfinite(o->line_width) &&
          o->line_width > 0 && isfinite(o->font_size) && o->font_size < 1000))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: outline_width = %g, line_width = %g, font_size = %g: widths "
                         "must be > 0 and the font size < 1000 (<= 0 = automatic)",
                         o->outline_width, o->line_width, o->font_size);
    const cdem_rgba *cols[] = {&o->background, &o->wall,       &o->pregrowth[0], &o->pregrowth[1],
                               &o->growth1[0], &o->growth1[1], &o->growth2[0],   &o->growth2[1],
                               &o->salt[0],    &o->salt[1],    &o->highlight,    &o->biaxial_edge,
                               &o->footwall,   &o->undefined,  &o->outline,      &o->vector,
                               &o->axis[0],    &o->axis[1],    &o->text};
    for (size_t k = 0; k < sizeof cols / sizeof cols[0]; k++)
        if (!colour_ok(cols[k]))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "render: colour #%zu of the options (%g, %g, %g, %g): channels "
                             "must be in 0..1",
                             k, cols[k]->r, cols[k]->g, cols[k]->b, cols[k]->a);
    return CDEM_OK;
}

static void view_box(const cdem_render_scene *sc, const cdem_render_options *o, double box[4]) {
    if (o->has_zoom) {
        box[0] = o->zoom_xmin;
        box[1] = o->zoom_xmax;
        box[2] = o->zoom_ymin;
        box[3] = o->zoom_ymax;
    } else {
        cdem_render_fit_box(sc->state, o->margin, box);
    }
}

static double font_size_for(const cdem_render_options *o, double width) {
    if (o->font_size > 0)
        return o->font_size;
    return fmax(9.0, width / 70.0);
}

/* Bands around the plot area: top (label), bottom (scale bar), right (colour bar or its
 * room). */
static void bands(const cdem_render_scene *sc, const cdem_render_options *o, double fs, double *pad,
                  double *top, double *bottom, double *right) {
    *pad = 0.8 * fs;
    *top = (o->show_label && sc->label && sc->label[0]) ? 2.2 * fs : *pad;
    *bottom = o->show_scale_bar ? 3.4 * fs : *pad;
    *right = colour_bar_room(sc, o) ? 10.0 * fs : *pad;
}

cdem_status cdem_render_auto_height(const cdem_render_scene *sc, const cdem_render_options *o,
                                    int *height, cdem_error *err) {
    CDEM_TRY(validate(sc, o, err));
    if (o->width < 16 || o->width > CDEM_RENDER_MAX_SIZE)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "render: width = %d: must be in 16..%d", o->width,
                         CDEM_RENDER_MAX_SIZE);
    double box[4], pad, top, bottom, right;
    view_box(sc, o, box);
    double fs = font_size_for(o, o->width);
    bands(sc, o, fs, &pad, &top, &bottom, &right);
    double pw = fmax(1.0, o->width - pad - right);
    double ph = pw * (box[3] - box[2]) / (box[1] - box[0]);
    if (colour_bar_room(sc, o))
        ph = fmax(ph, 8.0 * fs);
    double h = ceil(top + ph + bottom);
    if (!(h >= 16))
        h = 16;
    if (h > CDEM_RENDER_MAX_SIZE)
        h = CDEM_RENDER_MAX_SIZE;
    *height = (int)h;
    return CDEM_OK;
}

cdem_status cdem_render_layout_compute(const cdem_render_scene *sc, const cdem_render_options *o,
                                       double width, double height, cdem_render_layout *lay,
                                       cdem_error *err) {
    CDEM_TRY(validate(sc, o, err));
    if (!(width >= 16 && width <= CDEM_RENDER_MAX_SIZE && height >= 16 &&
          height <= CDEM_RENDER_MAX_SIZE))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: image size %g x %g: each side must be "
                         "in 16..%d",
                         width, height, CDEM_RENDER_MAX_SIZE);
    memset(lay, 0, sizeof *lay);
    double box[4], pad, top, bottom, right;
    view_box(sc, o, box);
    double fs = font_size_for(o, width);
    bands(sc, o, fs, &pad, &top, &bottom, &right);
    lay->width = width;
    lay->height = height;
    lay->font_size = fs;
    lay->xmin = box[0];
    lay->xmax = box[1];
    lay->ymin = box[2];
    lay->ymax = box[3];
    lay->plot_x = pad;
    lay->plot_y = top;
    lay->plot_w = fmax(1.0, width - pad - right);
    lay->plot_h = fmax(1.0, height - top - bottom);
    double bw = box[1] - box[0], bh = box[3] - box[2];
    lay->scale = fmin(lay->plot_w / bw, lay->plot_h / bh);
    lay->ox = lay->plot_x + 0.5 * (lay->plot_w - bw * lay->scale);
    lay->oy = lay->plot_y + 0.5 * (lay->plot_h - bh * lay->scale);
    if (has_colour_bar(sc, o)) {
        lay->bar_x = lay->plot_x + lay->plot_w + pad;
        lay->bar_w = 1.2 * fs;
        double h = fmax(bh * lay->scale, fmin(8.0 * fs, lay->plot_h));
        lay->bar_h = fmax(1.0, h - fs);
        lay->bar_y = lay->plot_y + 0.5 * (lay->plot_h - lay->bar_h);
    }
    return CDEM_OK;
}

void cdem_render_layout_to_device(const cdem_render_layout *lay, double x, double y, double *dx,
                                  double *dy) {
    *dx = lay->ox + (x - lay->xmin) * lay->scale;
    *dy = lay->oy + (lay->ymax - y) * lay->scale;
}

static void set_colour(cairo_t *cr, const cdem_rgba *c) {
    cairo_set_source_rgba(cr, c->r, c->g, c->b, c->a);
}

static int layer_slot(const cdem_render_options *o, int32_t layer) {
    if (o->highlight_first > 0 && layer >= o->highlight_first && layer <= o->highlight_last)
        return SLOT_HIGHLIGHT;
    if (layer >= 1 && layer <= o->pregrowth_layers)
        return SLOT_PRE0 + ((layer - 1) / o->band_layers) % 2;
    if (layer > o->pregrowth_layers) {
        long g = (long)layer - o->pregrowth_layers;
        if (g <= o->growth1_layers)
            return SLOT_G1_0 + (int)(((g - 1) / o->band_layers) % 2);
        return SLOT_G2_0 + (int)(((g - o->growth1_layers - 1) / o->band_layers) % 2);
    }
    return SLOT_PRE0;
}

/* Colour slot of element i (before the weak offset). */
static int element_slot(const cdem_render_scene *sc, const cdem_render_options *o, size_t i,
                        double threshold, double lo, double hi) {
    const cdem_state *s = sc->state;
    uint32_t f = s->flags ? s->flags[i] : 0;
    if (f & CDEM_FLAG_FOOTWALL)
        return SLOT_FOOTWALL;
    if (f & (CDEM_FLAG_WALL | CDEM_FLAG_FAULT | CDEM_FLAG_MYLAR))
        return SLOT_WALL;
    if (f & CDEM_FLAG_BIAXIAL_EDGE)
        return SLOT_EDGE;
    if (has_values(sc, o)) {
        double v = sc->values[i];
        if (isnan(v))
            return SLOT_UNDEFINED;
        if (!sc->above_tenth_max || fabs(v) > threshold) {
            double t =
                hi > lo ? (v - lo) / (hi - lo) : (sc->kind == CDEM_COLORMAP_SIGNED ? 0.5 : 0.0);
            t = t < 0 ? 0 : (t > 1 ? 1 : t);
            return SLOT_MAP + (int)floor(t * (MAP_BINS - 1) + 0.5);
        }
    }
    const int32_t layer = s->layer ? s->layer[i] : 0;
    const int slot = layer_slot(o, layer);
    if ((f & CDEM_FLAG_SALT) && slot != SLOT_HIGHLIGHT)
        return SLOT_SALT0 + (layer >= 1 ? ((layer - 1) / o->band_layers) % 2 : 0);
    return slot;
}

static void slot_colours(const cdem_render_scene *sc, const cdem_render_options *o,
                         cdem_rgba *pal) {
    pal[SLOT_WALL] = o->wall;
    pal[SLOT_FOOTWALL] = o->footwall;
    pal[SLOT_EDGE] = o->biaxial_edge;
    pal[SLOT_UNDEFINED] = o->undefined;
    pal[SLOT_HIGHLIGHT] = o->highlight;
    pal[SLOT_PRE0] = o->pregrowth[0];
    pal[SLOT_PRE1] = o->pregrowth[1];
    pal[SLOT_G1_0] = o->growth1[0];
    pal[SLOT_G1_1] = o->growth1[1];
    pal[SLOT_G2_0] = o->growth2[0];
    pal[SLOT_G2_1] = o->growth2[1];
    pal[SLOT_SALT0] = o->salt[0];
    pal[SLOT_SALT1] = o->salt[1];
    for (int k = 0; k < MAP_BINS; k++)
        pal[SLOT_MAP + k] = cdem_colormap_eval(sc->kind, (double)k / (MAP_BINS - 1));
    for (int k = 0; k < SLOT_FIXED_N; k++) {
        pal[SLOT_FIXED_N + k] = pal[k];
        pal[SLOT_FIXED_N + k].a = pal[k].a * o->weak_alpha;
    }
}

static int disc_visible(const cdem_render_layout *lay, double x, double y, double r) {
    return x + r >= lay->xmin && x - r <= lay->xmax && y + r >= lay->ymin && y - r <= lay->ymax;
}

static int point_visible(const cdem_render_layout *lay, double x, double y) {
    return isfinite(x) && isfinite(y) && x >= lay->xmin && x <= lay->xmax && y >= lay->ymin &&
           y <= lay->ymax;
}

/* Where line segments go: straight into the pixels (rt set) or into a cairo path that
 * line_sink_finish strokes. */
typedef struct {
    cairo_t *cr;                  /* the context (cairo path) */
    const cdem_raster_target *rt; /* direct target, or NULL */
    const cdem_rgba *colour;      /* line colour */
    double width;                 /* line width, device units */
} line_sink;

static void line_sink_segment(const line_sink *ls, double x0, double y0, double x1, double y1) {
    if (ls->rt) {
        cdem_raster_segment(ls->rt, x0, y0, x1, y1, ls->width, ls->colour);
    } else {
        cairo_move_to(ls->cr, x0, y0);
        cairo_line_to(ls->cr, x1, y1);
    }
}

static void line_sink_finish(const line_sink *ls) {
    if (ls->rt) {
        cairo_surface_mark_dirty(ls->rt->surface);
        return;
    }
    set_colour(ls->cr, ls->colour);
    cairo_set_line_width(ls->cr, ls->width);
    cairo_set_line_cap(ls->cr, CAIRO_LINE_CAP_ROUND);
    cairo_stroke(ls->cr);
}

static cdem_status draw_elements(cairo_t *cr, const cdem_raster_target *rtp,
                                 const cdem_render_layout *lay, const cdem_render_scene *sc,
                                 const cdem_render_options *o, cdem_error *err) {
    const cdem_state *s = sc->state;
    size_t n = s->n;
    if (n == 0)
        return CDEM_OK;
    uint16_t *slot = malloc(n * sizeof *slot);
    uint32_t *order = malloc(n * sizeof *order);
    size_t *start = calloc(SLOT_N + 1, sizeof *start);
    cdem_rgba *pal = malloc(SLOT_N * sizeof *pal);
    if (!slot || !order || !start || !pal) {
        free(slot);
        free(order);
        free(start);
        free(pal);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "render: out of memory for %zu elements", n);
    }
    double lo = 0, hi = 0, threshold = 0;
    if (sc->values) {
        cdem_colormap_limits(sc->kind, sc->vmin, sc->vmax, &lo, &hi);
        threshold = 0.1 * fmax(fabs(sc->vmin), fabs(sc->vmax));
    }
    const uint16_t hidden = (uint16_t)SLOT_N;
    for (size_t i = 0; i < n; i++) {
        if (!disc_ok(s, i) || !disc_visible(lay, s->x[i], s->y[i], s->radius[i])) {
            slot[i] = hidden;
            continue;
        }
        int k = element_slot(sc, o, i, threshold, lo, hi);
        if (s->flags && (s->flags[i] & CDEM_FLAG_WEAK))
            k += SLOT_FIXED_N;
        slot[i] = (uint16_t)k;
        start[k + 1]++;
    }
    for (int k = 0; k < SLOT_N; k++)
        start[k + 1] += start[k];
    size_t n_visible = start[SLOT_N];
    {
        size_t *fill = malloc(SLOT_N * sizeof *fill);
        if (!fill) {
            free(slot);
            free(order);
            free(start);
            free(pal);
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "render: out of memory for %zu elements", n);
        }
        memcpy(fill, start, SLOT_N * sizeof *fill);
        for (size_t i = 0; i < n; i++)
            if (slot[i] != hidden)
                order[fill[slot[i]]++] = (uint32_t)i;
        free(fill);
    }
    slot_colours(sc, o, pal);

    int outline = o->show_outline || !o->show_fill;
    if (rtp) {
        const cdem_raster_target rt = *rtp;
        for (int k = 0; o->show_fill && k < SLOT_N; k++)
            for (size_t j = start[k]; j < start[k + 1]; j++) {
                size_t i = order[j];
                double cx, cy;
                cdem_render_layout_to_device(lay, s->x[i], s->y[i], &cx, &cy);
                cdem_raster_disc(&rt, cx, cy, s->radius[i] * lay->scale, &pal[k], 0.0);
            }
        for (size_t j = 0; outline && j < n_visible; j++) {
            size_t i = order[j];
            double cx, cy;
            cdem_render_layout_to_device(lay, s->x[i], s->y[i], &cx, &cy);
            cdem_raster_disc(&rt, cx, cy, s->radius[i] * lay->scale, &o->outline, o->outline_width);
        }
        cairo_surface_mark_dirty(rt.surface);
    } else {
        cairo_save(cr);
        cairo_translate(cr, lay->ox - lay->xmin * lay->scale, lay->oy + lay->ymax * lay->scale);
        cairo_scale(cr, lay->scale, -lay->scale);
        for (int k = 0; o->show_fill && k < SLOT_N; k++) {
            if (start[k + 1] == start[k])
                continue;
            cairo_new_path(cr);
            for (size_t j = start[k]; j < start[k + 1]; j++) {
                size_t i = order[j];
                cairo_new_sub_path(cr);
                cairo_arc(cr, s->x[i], s->y[i], s->radius[i], 0.0, 2.0 * render_pi);
            }
            set_colour(cr, &pal[k]);
            cairo_fill(cr);
        }
        if (outline && n_visible > 0) {
            cairo_new_path(cr);
            for (size_t j = 0; j < n_visible; j++) {
                size_t i = order[j];
                cairo_new_sub_path(cr);
                cairo_arc(cr, s->x[i], s->y[i], s->radius[i], 0.0, 2.0 * render_pi);
            }
        }
        cairo_restore(cr); /* the path stays, in device space: widths are device units */
        if (outline && n_visible > 0) {
            set_colour(cr, &o->outline);
            cairo_set_line_width(cr, o->outline_width);
            cairo_stroke(cr);
        }
    }
    free(slot);
    free(order);
    free(start);
    free(pal);
    return CDEM_OK;
}

static void draw_vectors(cairo_t *cr, const cdem_raster_target *rt, const cdem_render_layout *lay,
                         const cdem_render_scene *sc, const cdem_render_options *o) {
    const cdem_state *s = sc->state;
    double lw = o->line_width;
    line_sink ls = {cr, rt, &o->vector, lw};
    cairo_new_path(cr);
    for (size_t i = 0; i < s->n; i++) {
        if (!point_visible(lay, s->x[i], s->y[i]))
            continue;
        double ux = sc->ux[i] * sc->vector_scale, uy = sc->uy[i] * sc->vector_scale;
        if (!isfinite(ux) || !isfinite(uy))
            continue;
        double x0, y0;
        cdem_render_layout_to_device(lay, s->x[i], s->y[i], &x0, &y0);
        double dx = ux * lay->scale, dy = -uy * lay->scale;
        double len = hypot(dx, dy);
        if (len < 0.5 || len > 4.0 * (lay->width + lay->height))
            continue;
        double x1 = x0 + dx, y1 = y0 + dy;
        line_sink_segment(&ls, x0, y0, x1, y1);
        double head = fmin(0.35 * len, 4.0 * lw + 2.0);
        double ex = dx / len, ey = dy / len;
        line_sink_segment(&ls, x1 - head * (ex + 0.5 * ey), y1 - head * (ey - 0.5 * ex), x1, y1);
        line_sink_segment(&ls, x1 - head * (ex - 0.5 * ey), y1 - head * (ey + 0.5 * ex), x1, y1);
    }
    line_sink_finish(&ls);
}

static void draw_axes(cairo_t *cr, const cdem_raster_target *rt, const cdem_render_layout *lay,
                      const cdem_render_scene *sc, const cdem_render_options *o) {
    double len = sc->axis_length;
    if (!(len > 0)) {
        double rmax = 0;
        for (size_t i = 0; i < sc->state->n; i++)
            if (disc_ok(sc->state, i))
                rmax = fmax(rmax, sc->state->radius[i]);
        len = 1.6 * (rmax > 0 ? rmax : 1.0);
    }
    double half = 0.5 * len * lay->scale;
    int sets = sc->axis_perpendicular ? 2 : 1;
    for (int set = 0; set < sets; set++) {
        line_sink ls = {cr, rt, &o->axis[set], o->line_width};
        cairo_new_path(cr);
        for (size_t k = 0; k < sc->n_axes; k++) {
            double a = sc->axis_angle[k] + (set ? 0.5 * render_pi : 0.0);
            if (!isfinite(a) || !point_visible(lay, sc->axis_x[k], sc->axis_y[k]))
                continue;
            double cx, cy;
            cdem_render_layout_to_device(lay, sc->axis_x[k], sc->axis_y[k], &cx, &cy);
            double ex = cos(a) * half, ey = -sin(a) * half; /* device y points down */
            line_sink_segment(&ls, cx - ex, cy - ey, cx + ex, cy + ey);
        }
        line_sink_finish(&ls);
    }
}

/* Largest 1, 2 or 5 x 10^k not above target (target > 0). */
static double nice_length(double target) {
    double p = pow(10.0, floor(log10(target)));
    double m = target / p;
    return (m >= 5 ? 5 : (m >= 2 ? 2 : 1)) * p;
}

static void draw_scale_bar(cairo_t *cr, const cdem_render_layout *lay,
                           const cdem_render_options *o) {
    double visible_w = fmin(lay->xmax - lay->xmin, lay->plot_w / lay->scale);
    double len_m = nice_length(0.2 * visible_w);
    double len_px = len_m * lay->scale;
    double fs = lay->font_size;
    double x0 = lay->plot_x + 0.5 * fs;
    double y0 = lay->plot_y + lay->plot_h + 0.6 * fs;
    double h = 0.4 * fs;
    set_colour(cr, &o->text);
    cairo_new_path(cr);
    cairo_rectangle(cr, x0, y0, len_px, h);
    cairo_fill(cr);
    char text[64];
    if (len_m >= 1000.0)
        snprintf(text, sizeof text, "%g km", len_m / 1000.0);
    else
        snprintf(text, sizeof text, "%g m", len_m);
    cairo_text_extents_t te;
    cairo_text_extents(cr, text, &te);
    cairo_move_to(cr, x0 + 0.5 * len_px - (te.x_bearing + 0.5 * te.width), y0 + h + 1.3 * fs);
    cairo_show_text(cr, text);
}

static void draw_colour_bar(cairo_t *cr, const cdem_render_layout *lay, const cdem_render_scene *sc,
                            const cdem_render_options *o) {
    double x = lay->bar_x, y = lay->bar_y, w = lay->bar_w, h = lay->bar_h;
    cairo_pattern_t *pat = cairo_pattern_create_linear(0.0, y + h, 0.0, y);
    const int stops = 128;
    for (int k = 0; k <= stops; k++) {
        double t = (double)k / stops;
        cdem_rgba c = cdem_colormap_eval(sc->kind, t);
        cairo_pattern_add_color_stop_rgb(pat, t, c.r, c.g, c.b);
    }
    cairo_new_path(cr);
    cairo_rectangle(cr, x, y, w, h);
    cairo_set_source(cr, pat);
    cairo_fill(cr);
    cairo_pattern_destroy(pat);

    double fs = lay->font_size;
    set_colour(cr, &o->text);
    cairo_set_line_width(cr, fmax(0.5, o->line_width * 0.75));
    cairo_new_path(cr);
    cairo_rectangle(cr, x - 0.5, y - 0.5, w + 1.0, h + 1.0);
    cairo_stroke(cr);
    double lo, hi;
    cdem_colormap_limits(sc->kind, sc->vmin, sc->vmax, &lo, &hi);
    /* five ticks with labels that differ; one, in the middle, for a range of one value */
    const int ticks = hi > lo ? 5 : 1;
    char labels[5][CDEM_COLORMAP_TICK_CHARS];
    cdem_colormap_tick_labels(lo, hi, ticks, labels);
    double text_w = 0;
    for (int k = 0; k < ticks; k++) {
        double f = ticks > 1 ? (double)k / (ticks - 1) : 0.5;
        double ty = y + h - f * h;
        cairo_new_path(cr);
        cairo_move_to(cr, x + w, ty);
        cairo_line_to(cr, x + w + 0.4 * fs, ty);
        cairo_stroke(cr);
        const char *text = labels[k];
        cairo_text_extents_t te;
        cairo_text_extents(cr, text, &te);
        text_w = fmax(text_w, te.x_advance);
        cairo_move_to(cr, x + w + 0.6 * fs, ty - (te.y_bearing + 0.5 * te.height));
        cairo_show_text(cr, text);
    }
    if (sc->quantity && sc->quantity[0]) {
        char title[256];
        if (sc->unit && sc->unit[0])
            snprintf(title, sizeof title, "%s (%s)", sc->quantity, sc->unit);
        else
            snprintf(title, sizeof title, "%s", sc->quantity);
        if (sc->above_tenth_max && strlen(title) + 16 < sizeof title)
            strcat(title, ", > 0.1 max");
        cairo_text_extents_t te;
        cairo_text_extents(cr, title, &te);
        cairo_save(cr);
        cairo_translate(cr, x + w + 0.9 * fs + text_w + 0.2 * fs, y + 0.5 * h);
        cairo_rotate(cr, 0.5 * render_pi);
        cairo_move_to(cr, -(te.x_bearing + 0.5 * te.width), -te.y_bearing - 0.5 * te.height);
        cairo_show_text(cr, title);
        cairo_restore(cr);
    }
}

cdem_status cdem_render_draw(cairo_t *cr, double width, double height, const cdem_render_scene *sc,
                             const cdem_render_options *o, cdem_error *err) {
    if (!cr)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "render: cairo context is NULL");
    cdem_render_layout lay;
    CDEM_TRY(cdem_render_layout_compute(sc, o, width, height, &lay, err));

    cairo_save(cr);
    cairo_set_operator(cr, CAIRO_OPERATOR_SOURCE);
    set_colour(cr, &o->background);
    cairo_paint(cr);
    cairo_set_operator(cr, CAIRO_OPERATOR_OVER);
    cairo_select_font_face(cr, "sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, lay.font_size);

    cairo_save(cr);
    cairo_new_path(cr);
    cairo_rectangle(cr, lay.plot_x, lay.plot_y, lay.plot_w, lay.plot_h);
    cairo_clip(cr);
    cdem_raster_target rt;
    const cdem_raster_target *rtp =
        cdem_raster_target_get(cr, lay.plot_x, lay.plot_y, lay.plot_w, lay.plot_h, &rt) ? &rt
                                                                                        : NULL;
    cdem_status st = draw_elements(cr, rtp, &lay, sc, o, err);
    if (st != CDEM_OK) {
        cairo_restore(cr);
        cairo_restore(cr);
        return st;
    }
    if (sc->ux && o->show_vectors)
        draw_vectors(cr, rtp, &lay, sc, o);
    if (sc->n_axes > 0 && o->show_axes)
        draw_axes(cr, rtp, &lay, sc, o);
    cairo_restore(cr);

    if (o->show_label && sc->label && sc->label[0]) {
        set_colour(cr, &o->text);
        cairo_move_to(cr, lay.plot_x + 0.5 * lay.font_size, 1.5 * lay.font_size);
        cairo_show_text(cr, sc->label);
    }
    if (o->show_scale_bar)
        draw_scale_bar(cr, &lay, o);
    if (has_colour_bar(sc, o))
        draw_colour_bar(cr, &lay, sc, o);
    cairo_restore(cr);
    cairo_status_t cs = cairo_status(cr);
    if (cs != CAIRO_STATUS_SUCCESS)
        return CDEM_FAIL(err, CDEM_ERR_IO, "render: cairo failed while drawing: %s",
                         cairo_status_to_string(cs));
    return CDEM_OK;
}

cdem_status cdem_render_to_surface(cairo_surface_t *surface, const cdem_render_scene *sc,
                                   const cdem_render_options *o, cdem_error *err) {
    if (!surface || cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS ||
        cairo_surface_get_type(surface) != CAIRO_SURFACE_TYPE_IMAGE)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "render: the target must be a valid cairo image surface");
    int w = cairo_image_surface_get_width(surface), h = cairo_image_surface_get_height(surface);
    cairo_t *cr = cairo_create(surface);
    cdem_status st = cdem_render_draw(cr, w, h, sc, o, err);
    cairo_destroy(cr);
    cairo_surface_flush(surface);
    return st;
}

cdem_status cdem_render_to_rgba(uint8_t *rgba, int width, int height, const cdem_render_scene *sc,
                                const cdem_render_options *o, cdem_error *err) {
    if (!rgba)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "render: RGBA buffer is NULL");
    if (width < 16 || width > CDEM_RENDER_MAX_SIZE || height < 16 || height > CDEM_RENDER_MAX_SIZE)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: image size %d x %d: each side must be "
                         "in 16..%d",
                         width, height, CDEM_RENDER_MAX_SIZE);
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height);
    if (cairo_surface_status(surf) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(surf);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "render: cannot create a %d x %d image", width,
                         height);
    }
    cdem_status st = cdem_render_to_surface(surf, sc, o, err);
    if (st == CDEM_OK) {
        const unsigned char *data = cairo_image_surface_get_data(surf);
        int stride = cairo_image_surface_get_stride(surf);
        for (int y = 0; y < height; y++) {
            const uint32_t *row = (const uint32_t *)(const void *)(data + (size_t)y * stride);
            uint8_t *out = rgba + (size_t)y * width * 4;
            for (int x = 0; x < width; x++) {
                uint32_t p = row[x];
                unsigned a = p >> 24, r = (p >> 16) & 255, g = (p >> 8) & 255, b = p & 255;
                if (a != 0 && a != 255) { /* undo premultiplication */
                    r = (r * 255 + a / 2) / a;
                    g = (g * 255 + a / 2) / a;
                    b = (b * 255 + a / 2) / a;
                }
                out[4 * x + 0] = (uint8_t)(r > 255 ? 255 : r);
                out[4 * x + 1] = (uint8_t)(g > 255 ? 255 : g);
                out[4 * x + 2] = (uint8_t)(b > 255 ? 255 : b);
                out[4 * x + 3] = (uint8_t)a;
            }
        }
    }
    cairo_surface_destroy(surf);
    return st;
}

cdem_status cdem_render_to_file(const char *path, const cdem_render_scene *sc,
                                const cdem_render_options *o, cdem_error *err) {
    cdem_render_format fmt;
    CDEM_TRY(cdem_render_format_from_path(path, &fmt, err));
    CDEM_TRY(validate(sc, o, err));
    int w = o->width, h = o->height;
    if (h == 0)
        CDEM_TRY(cdem_render_auto_height(sc, o, &h, err));
    if (w < 16 || w > CDEM_RENDER_MAX_SIZE || h < 16 || h > CDEM_RENDER_MAX_SIZE)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "render: image size %d x %d: each side must be in 16..%d (height 0 = "
                         "automatic)",
                         w, h, CDEM_RENDER_MAX_SIZE);
    cdem_render_target t;
    CDEM_TRY(cdem_render_target_open(&t, path, fmt, w, h, "render", err));
    cairo_t *cr = cairo_create(t.surf);
    cdem_status st = cdem_render_draw(cr, w, h, sc, o, err);
    cairo_destroy(cr);
    return cdem_render_target_close(&t, st, err);
}

cdem_status cdem_render_target_open(cdem_render_target *t, const char *path, cdem_render_format fmt,
                                    int w, int h, const char *what, cdem_error *err) {
    t->fmt = fmt;
    t->path = path;
    t->what = what;
    t->surf = NULL;
    CDEM_TRY(cdem_outfile_begin(&t->of, path, err));
    if (fmt == CDEM_RENDER_PNG)
        t->surf = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, w, h);
    else if (fmt == CDEM_RENDER_PDF)
        t->surf = cairo_pdf_surface_create(t->of.tmp, w, h);
    else
        t->surf = cairo_svg_surface_create(t->of.tmp, w, h);
    cairo_status_t cs = cairo_surface_status(t->surf);
    if (cs != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(t->surf);
        t->surf = NULL;
        return cdem_outfile_end(&t->of,
                                CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot create image file '%s': %s",
                                          what, path, cairo_status_to_string(cs)),
                                err);
    }
    return CDEM_OK;
}

cdem_status cdem_render_target_close(cdem_render_target *t, cdem_status st, cdem_error *err) {
    if (st == CDEM_OK) {
        cairo_status_t cs;
        if (t->fmt == CDEM_RENDER_PNG)
            cs = cairo_surface_write_to_png(t->surf, t->of.tmp);
        else {
            cairo_surface_finish(t->surf);
            cs = cairo_surface_status(t->surf);
        }
        if (cs != CAIRO_STATUS_SUCCESS)
            st = CDEM_FAIL(err, CDEM_ERR_IO, "%s: cannot write image file '%s': %s", t->what,
                           t->path, cairo_status_to_string(cs));
    }
    cairo_surface_destroy(t->surf);
    t->surf = NULL;
    return cdem_outfile_end(&t->of, st, err);
}
