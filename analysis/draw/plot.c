/* plot: cairo line plots (see plot.h). */
#include "plot.h"

#include "render.h"

#include "outfile.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Ten colours (matplotlib's tab10): ten series without colours of their own differ by
 * colour, more by dash pattern too (cdem_plot_series_style; issue 46: ten biaxial curves of
 * `calibrate` on an eight-colour cycle drew two pairs alike). */
static const cdem_rgba plot_palette[CDEM_PLOT_PALETTE_N] = {
    {0.12, 0.47, 0.71, 1}, {0.84, 0.15, 0.16, 1}, {0.17, 0.63, 0.17, 1}, {1.00, 0.50, 0.05, 1},
    {0.58, 0.40, 0.74, 1}, {0.55, 0.34, 0.29, 1}, {0.89, 0.47, 0.76, 1}, {0.50, 0.50, 0.50, 1},
    {0.74, 0.74, 0.13, 1}, {0.09, 0.75, 0.81, 1},
};

cdem_rgba cdem_plot_palette(size_t i) {
    return plot_palette[i % CDEM_PLOT_PALETTE_N];
}

void cdem_plot_series_style(const cdem_plot_series *s, size_t i, cdem_rgba *colour,
                            cdem_plot_dash *dash) {
    const int own = s->colour.a > 0;
    *colour = own ? s->colour : cdem_plot_palette(i);
    if (s->dashed)
        *dash = CDEM_PLOT_DASHED;
    else if (own)
        *dash = CDEM_PLOT_SOLID;
    else
        *dash = (cdem_plot_dash)((i / CDEM_PLOT_PALETTE_N) % 3);
}

void cdem_plot_nice_ticks(double lo, double hi, int target, double *first, double *step) {
    if (target < 2)
        target = 2;
    double raw = (hi - lo) / target;
    if (!(raw > 0) || !isfinite(raw))
        raw = 1.0;
    double mag = pow(10.0, floor(log10(raw)));
    double f = raw / mag;
    double s = f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0;
    *step = s * mag;
    *first = ceil(lo / *step - 1e-9) * *step;
}

static cdem_status check_panel(const cdem_plot *p, cdem_error *err) {
    if (!p)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "plot: panel is NULL");
    if (p->n_series && !p->series)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "plot: %zu series but the series array is NULL",
                         p->n_series);
    for (size_t i = 0; i < p->n_series; i++)
        if (p->series[i].n && (!p->series[i].x || !p->series[i].y))
            return CDEM_FAIL(err, CDEM_ERR_INVALID,
                             "plot: series %zu ('%s') has %zu points but no x or y array", i,
                             p->series[i].label ? p->series[i].label : "", p->series[i].n);
    if (p->fix_x && !(isfinite(p->xmin) && isfinite(p->xmax) && p->xmin < p->xmax))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "plot: fixed x range %g .. %g: need finite xmin < xmax", p->xmin, p->xmax);
    if (p->fix_y && !(isfinite(p->ymin) && isfinite(p->ymax) && p->ymin < p->ymax))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "plot: fixed y range %g .. %g: need finite ymin < ymax", p->ymin, p->ymax);
    return CDEM_OK;
}

/* Data range of one axis (0: x, 1: y) over all series, extended to whole ticks. */
static void axis_range(const cdem_plot *p, int axis, double *lo, double *hi, double *first,
                       double *step) {
    double a = INFINITY, b = -INFINITY;
    for (size_t i = 0; i < p->n_series; i++) {
        const cdem_plot_series *s = &p->series[i];
        for (size_t k = 0; k < s->n; k++) {
            double v = axis ? s->y[k] : s->x[k];
            if (isfinite(v) && isfinite(axis ? s->x[k] : s->y[k])) {
                a = fmin(a, v);
                b = fmax(b, v);
            }
        }
    }
    if (!(a <= b)) {
        a = 0.0;
        b = 1.0;
    } else if (a == b) {
        double d = a != 0.0 ? 0.5 * fabs(a) : 1.0;
        a -= d;
        b += d;
    }
    cdem_plot_nice_ticks(a, b, 6, first, step);
    *lo = floor(a / *step + 1e-9) * *step;
    *hi = ceil(b / *step - 1e-9) * *step;
    if (*hi <= *lo)
        *hi = *lo + *step;
    *first = *lo;
}

cdem_status cdem_plot_layout_compute(const cdem_plot *p, double x, double y, double w, double h,
                                     cdem_plot_layout *lay, cdem_error *err) {
    CDEM_TRY(check_panel(p, err));
    memset(lay, 0, sizeof *lay);
    double fs = fmin(w, h) / 40.0;
    fs = fs < 9.0 ? 9.0 : fs > 24.0 ? 24.0 : fs;
    lay->font_size = fs;
    double left = 6.5 * fs, right = 1.5 * fs, top = 2.4 * fs, bottom = 3.6 * fs;
    lay->plot_x = x + left;
    lay->plot_y = y + top;
    lay->plot_w = w - left - right;
    lay->plot_h = h - top - bottom;
    if (!(lay->plot_w >= 8.0 && lay->plot_h >= 8.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "plot: panel box %.0f x %.0f is too small for the axes (font %.0f)", w, h,
                         fs);
    if (p->fix_x) {
        lay->xmin = p->xmin;
        lay->xmax = p->xmax;
        cdem_plot_nice_ticks(p->xmin, p->xmax, 6, &lay->xtick0, &lay->xstep);
    } else {
        axis_range(p, 0, &lay->xmin, &lay->xmax, &lay->xtick0, &lay->xstep);
    }
    if (p->fix_y) {
        lay->ymin = p->ymin;
        lay->ymax = p->ymax;
        cdem_plot_nice_ticks(p->ymin, p->ymax, 6, &lay->ytick0, &lay->ystep);
    } else {
        axis_range(p, 1, &lay->ymin, &lay->ymax, &lay->ytick0, &lay->ystep);
    }
    if (p->equal_aspect) {
        double sx = lay->plot_w / (lay->xmax - lay->xmin);
        double sy = lay->plot_h / (lay->ymax - lay->ymin);
        if (sx > sy) { /* widen x */
            double half = 0.5 * lay->plot_w / sy, c = 0.5 * (lay->xmin + lay->xmax);
            lay->xmin = c - half;
            lay->xmax = c + half;
            cdem_plot_nice_ticks(lay->xmin, lay->xmax, 6, &lay->xtick0, &lay->xstep);
        } else if (sy > sx) { /* heighten y */
            double half = 0.5 * lay->plot_h / sx, c = 0.5 * (lay->ymin + lay->ymax);
            lay->ymin = c - half;
            lay->ymax = c + half;
            cdem_plot_nice_ticks(lay->ymin, lay->ymax, 6, &lay->ytick0, &lay->ystep);
        }
    }
    return CDEM_OK;
}

void cdem_plot_to_device(const cdem_plot_layout *lay, double x, double y, double *dx, double *dy) {
    *dx = lay->plot_x + (x - lay->xmin) / (lay->xmax - lay->xmin) * lay->plot_w;
    *dy = lay->plot_y + (lay->ymax - y) / (lay->ymax - lay->ymin) * lay->plot_h;
}

static void set_rgba(cairo_t *cr, const cdem_rgba *c) {
    cairo_set_source_rgba(cr, c->r, c->g, c->b, c->a);
}

static void tick_text(double v, double step, char *buf, size_t n) {
    if (fabs(v) < 1e-9 * step)
        v = 0.0;
    snprintf(buf, n, "%.6g", v);
}

static void text_at(cairo_t *cr, const char *s, double x, double y, double ax, double ay) {
    cairo_text_extents_t te;
    cairo_text_extents(cr, s, &te);
    cairo_move_to(cr, x - ax * te.x_advance - te.x_bearing, y - ay * te.height - te.y_bearing);
    cairo_show_text(cr, s);
}

/* Sets the dash pattern of a line of width lw. */
static void set_dash(cairo_t *cr, cdem_plot_dash dash, double lw) {
    if (dash == CDEM_PLOT_DASHED) {
        double d[2] = {4 * lw, 3 * lw};
        cairo_set_dash(cr, d, 2, 0);
    } else if (dash == CDEM_PLOT_DOTTED) {
        double d[2] = {1.2 * lw, 2.2 * lw};
        cairo_set_dash(cr, d, 2, 0);
    } else {
        cairo_set_dash(cr, NULL, 0, 0);
    }
}

static void draw_series(cairo_t *cr, const cdem_plot_layout *lay, const cdem_plot_series *s,
                        size_t i) {
    cdem_rgba c;
    cdem_plot_dash dash;
    cdem_plot_series_style(s, i, &c, &dash);
    set_rgba(cr, &c);
    double lw = fmax(1.0, lay->font_size / 7.0);
    cairo_set_line_width(cr, lw);
    set_dash(cr, dash, lw);
    if (s->line || !s->markers) {
        int open = 0;
        for (size_t k = 0; k < s->n; k++) {
            if (!isfinite(s->x[k]) || !isfinite(s->y[k])) {
                open = 0;
                continue;
            }
            double dx, dy;
            cdem_plot_to_device(lay, s->x[k], s->y[k], &dx, &dy);
            if (open)
                cairo_line_to(cr, dx, dy);
            else
                cairo_move_to(cr, dx, dy);
            open = 1;
        }
        cairo_stroke(cr);
    }
    cairo_set_dash(cr, NULL, 0, 0);
    if (s->markers)
        for (size_t k = 0; k < s->n; k++) {
            if (!isfinite(s->x[k]) || !isfinite(s->y[k]))
                continue;
            double dx, dy;
            cdem_plot_to_device(lay, s->x[k], s->y[k], &dx, &dy);
            cairo_new_sub_path(cr);
            cairo_arc(cr, dx, dy, 2.0 * lw + 1.0, 0, 2 * M_PI);
            cairo_fill(cr);
        }
}

static int boxes_overlap(const double a[4], const double b[4]) {
    return a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3];
}

static int inside(const double box[4], double x, double y) {
    return x >= box[0] && x <= box[0] + box[2] && y >= box[1] && y <= box[1] + box[3];
}

size_t cdem_plot_points_in_box(const cdem_plot *p, const cdem_plot_layout *lay,
                               const double box[4]) {
    size_t count = 0;
    for (size_t i = 0; i < p->n_series; i++) {
        const cdem_plot_series *s = &p->series[i];
        const int line = s->line || !s->markers;
        double px = 0, py = 0;
        int open = 0;
        for (size_t k = 0; k < s->n; k++) {
            if (!isfinite(s->x[k]) || !isfinite(s->y[k])) {
                open = 0;
                continue;
            }
            double dx, dy;
            cdem_plot_to_device(lay, s->x[k], s->y[k], &dx, &dy);
            count += inside(box, dx, dy);
            if (line && open) { /* every 2 px along the segment */
                double len = hypot(dx - px, dy - py);
                int m = len < 1e6 ? (int)(len / 2.0) : 500000;
                for (int j = 1; j < m; j++) {
                    double t = (double)j / m;
                    count += inside(box, px + t * (dx - px), py + t * (dy - py));
                }
            }
            px = dx;
            py = dy;
            open = 1;
        }
    }
    return count;
}

/* Device box of the tag of series i: centred above its highest point or below it (inside a
 * Mohr circle), whichever covers fewer of the points drawn (above when even), and within
 * the plot area. 0 when the series has no tag or no finite point. */
static int tag_box(cairo_t *cr, const cdem_plot *p, size_t i, const cdem_plot_layout *lay,
                   double box[4]) {
    const cdem_plot_series *s = &p->series[i];
    if (!s->tag || !s->tag[0])
        return 0;
    size_t top = s->n;
    for (size_t k = 0; k < s->n; k++)
        if (isfinite(s->x[k]) && isfinite(s->y[k]) && (top == s->n || s->y[k] > s->y[top]))
            top = k;
    if (top == s->n)
        return 0;
    double dx, dy, fs = lay->font_size;
    cdem_plot_to_device(lay, s->x[top], s->y[top], &dx, &dy);
    cairo_text_extents_t te;
    cairo_text_extents(cr, s->tag, &te);
    double w = te.x_advance + 0.4 * fs, h = 1.2 * fs;
    double x = fmin(fmax(dx - 0.5 * w, lay->plot_x), lay->plot_x + lay->plot_w - w);
    double above[4] = {x, fmax(dy - 0.2 * fs - h, lay->plot_y), w, h};
    double below[4] = {x, fmin(dy + 0.2 * fs, lay->plot_y + lay->plot_h - h), w, h};
    const int up = cdem_plot_points_in_box(p, lay, above) <= cdem_plot_points_in_box(p, lay, below);
    memcpy(box, up ? above : below, 4 * sizeof *box);
    return 1;
}

/* The tags drawn: drawn[i] = 1 with its box when series i's tag covers no earlier one. */
static void place_tags(cairo_t *cr, const cdem_plot *p, const cdem_plot_layout *lay,
                       double (*boxes)[4], int *drawn) {
    for (size_t i = 0; i < p->n_series; i++) {
        drawn[i] = tag_box(cr, p, i, lay, boxes[i]);
        for (size_t j = 0; drawn[i] && j < i; j++)
            if (drawn[j] && boxes_overlap(boxes[i], boxes[j]))
                drawn[i] = 0;
    }
}

/* The legend's box (see cdem_plot_legend_box), with cr's font for the text widths; *rows
 * gets the number of labelled series. */
static int legend_box_cr(cairo_t *cr, const cdem_plot *p, const cdem_plot_layout *lay,
                         double box[4], size_t *rows) {
    double fs = lay->font_size, wmax = 0;
    size_t n = 0;
    for (size_t i = 0; i < p->n_series; i++) {
        const char *l = p->series[i].label;
        if (!l || !l[0])
            continue;
        cairo_text_extents_t te;
        cairo_text_extents(cr, l, &te);
        wmax = fmax(wmax, te.x_advance);
        n++;
    }
    *rows = n;
    if (!n || p->no_legend)
        return 0;
    double bw = wmax + 4.0 * fs, bh = n * 1.4 * fs + 0.6 * fs;
    double left = lay->plot_x + 0.5 * fs, right = lay->plot_x + lay->plot_w - bw - 0.5 * fs;
    double top = lay->plot_y + 0.5 * fs, bottom = lay->plot_y + lay->plot_h - bh - 0.5 * fs;
    const double corner[4][2] = {{right, top}, {left, top}, {right, bottom}, {left, bottom}};
    double(*tags)[4] = p->n_series ? malloc(p->n_series * sizeof *tags) : NULL;
    int *drawn = p->n_series ? malloc(p->n_series * sizeof *drawn) : NULL;
    if (tags && drawn)
        place_tags(cr, p, lay, tags, drawn);
    size_t best_count = SIZE_MAX;
    for (int c = 0; c < 4; c++) {
        double b[4] = {corner[c][0], corner[c][1], bw, bh};
        size_t count = cdem_plot_points_in_box(p, lay, b);
        for (size_t i = 0; tags && drawn && i < p->n_series; i++)
            if (drawn[i] && boxes_overlap(b, tags[i]))
                count += 1000; /* a tag weighs as much as a stretch of line */
        if (count < best_count) {
            best_count = count;
            memcpy(box, b, sizeof b);
        }
    }
    free(tags);
    free(drawn);
    return 1;
}

int cdem_plot_legend_box(const cdem_plot *p, const cdem_plot_layout *lay, double box[4]) {
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, 1);
    cairo_t *cr = cairo_create(surf);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, lay->font_size);
    size_t rows;
    int has = legend_box_cr(cr, p, lay, box, &rows);
    cairo_destroy(cr);
    cairo_surface_destroy(surf);
    return has;
}

static void draw_tags(cairo_t *cr, const cdem_plot *p, const cdem_plot_layout *lay) {
    if (!p->n_series)
        return;
    double(*boxes)[4] = malloc(p->n_series * sizeof *boxes);
    int *drawn = malloc(p->n_series * sizeof *drawn);
    if (boxes && drawn) {
        place_tags(cr, p, lay, boxes, drawn);
        for (size_t i = 0; i < p->n_series; i++) {
            if (!drawn[i])
                continue;
            cdem_rgba c;
            cdem_plot_dash dash;
            cdem_plot_series_style(&p->series[i], i, &c, &dash);
            cairo_set_source_rgba(cr, 1, 1, 1, 0.85); /* lines crossing it stay behind */
            cairo_rectangle(cr, boxes[i][0], boxes[i][1], boxes[i][2], boxes[i][3]);
            cairo_fill(cr);
            set_rgba(cr, &c);
            text_at(cr, p->series[i].tag, boxes[i][0] + 0.5 * boxes[i][2],
                    boxes[i][1] + 0.5 * boxes[i][3], 0.5, 0.5);
        }
    }
    free(boxes);
    free(drawn);
}

static void draw_legend(cairo_t *cr, const cdem_plot *p, const cdem_plot_layout *lay) {
    double fs = lay->font_size, box[4];
    size_t n;
    if (!legend_box_cr(cr, p, lay, box, &n))
        return;
    double row = 1.4 * fs, bx = box[0], by = box[1];
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_rectangle(cr, bx, by, box[2], box[3]);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
    cairo_set_line_width(cr, 0.8);
    cairo_stroke(cr);
    size_t r = 0;
    for (size_t i = 0; i < p->n_series; i++) {
        const cdem_plot_series *s = &p->series[i];
        if (!s->label || !s->label[0])
            continue;
        double cy = by + 0.3 * fs + (r + 0.5) * row;
        cdem_rgba c;
        cdem_plot_dash dash;
        cdem_plot_series_style(s, i, &c, &dash);
        set_rgba(cr, &c);
        double lw = fmax(1.0, fs / 7.0);
        cairo_set_line_width(cr, lw);
        if (s->line || !s->markers) {
            set_dash(cr, dash, lw);
            cairo_move_to(cr, bx + 0.5 * fs, cy);
            cairo_line_to(cr, bx + 2.5 * fs, cy);
            cairo_stroke(cr);
            cairo_set_dash(cr, NULL, 0, 0);
        }
        if (s->markers) {
            cairo_arc(cr, bx + 1.5 * fs, cy, 0.25 * fs, 0, 2 * M_PI);
            cairo_fill(cr);
        }
        cairo_set_source_rgb(cr, 0, 0, 0);
        text_at(cr, s->label, bx + 3.2 * fs, cy, 0.0, 0.5);
        r++;
    }
}

cdem_status cdem_plot_draw(cairo_t *cr, const cdem_plot *p, double x, double y, double w, double h,
                           cdem_plot_layout *lay_out, cdem_error *err) {
    cdem_plot_layout lay;
    CDEM_TRY(cdem_plot_layout_compute(p, x, y, w, h, &lay, err));
    if (lay_out)
        *lay_out = lay;
    double fs = lay.font_size;
    cairo_save(cr);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, fs);
    char buf[64];
    /* grid and tick labels */
    cairo_set_line_width(cr, 0.6);
    for (int k = 0; k < 200; k++) {
        double v = lay.xtick0 + k * lay.xstep;
        if (v > lay.xmax + 1e-9 * lay.xstep)
            break;
        double dx, dy;
        cdem_plot_to_device(&lay, v, lay.ymin, &dx, &dy);
        cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
        cairo_move_to(cr, dx, lay.plot_y);
        cairo_line_to(cr, dx, lay.plot_y + lay.plot_h);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        tick_text(v, lay.xstep, buf, sizeof buf);
        text_at(cr, buf, dx, lay.plot_y + lay.plot_h + 0.4 * fs, 0.5, 0.0);
    }
    for (int k = 0; k < 200; k++) {
        double v = lay.ytick0 + k * lay.ystep;
        if (v > lay.ymax + 1e-9 * lay.ystep)
            break;
        double dx, dy;
        cdem_plot_to_device(&lay, lay.xmin, v, &dx, &dy);
        cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
        cairo_move_to(cr, lay.plot_x, dy);
        cairo_line_to(cr, lay.plot_x + lay.plot_w, dy);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        tick_text(v, lay.ystep, buf, sizeof buf);
        text_at(cr, buf, lay.plot_x - 0.4 * fs, dy, 1.0, 0.5);
    }
    /* series, clipped to the plot area */
    cairo_save(cr);
    cairo_rectangle(cr, lay.plot_x, lay.plot_y, lay.plot_w, lay.plot_h);
    cairo_clip(cr);
    for (size_t i = 0; i < p->n_series; i++)
        draw_series(cr, &lay, &p->series[i], i);
    draw_tags(cr, p, &lay);
    cairo_restore(cr);
    /* frame, labels, title, legend */
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1.0);
    cairo_rectangle(cr, lay.plot_x, lay.plot_y, lay.plot_w, lay.plot_h);
    cairo_stroke(cr);
    if (p->xlabel)
        text_at(cr, p->xlabel, lay.plot_x + 0.5 * lay.plot_w, lay.plot_y + lay.plot_h + 2.0 * fs,
                0.5, 0.0);
    if (p->ylabel) {
        cairo_save(cr);
        cairo_translate(cr, x + 0.3 * fs, lay.plot_y + 0.5 * lay.plot_h);
        cairo_rotate(cr, -M_PI / 2);
        text_at(cr, p->ylabel, 0, 0, 0.5, 0.0);
        cairo_restore(cr);
    }
    if (p->title)
        text_at(cr, p->title, lay.plot_x + 0.5 * lay.plot_w, y + 0.5 * fs, 0.5, 0.0);
    draw_legend(cr, p, &lay);
    cairo_restore(cr);
    return CDEM_OK;
}

cdem_status cdem_plot_to_file(const char *path, const cdem_plot *panels, size_t n_panels, int width,
                              int height, cdem_error *err) {
    cdem_render_format fmt;
    CDEM_TRY(cdem_render_format_from_path(path, &fmt, err));
    if (width < 16 || width > CDEM_RENDER_MAX_SIZE || height < 16 || height > CDEM_RENDER_MAX_SIZE)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "plot: image size %d x %d: each side must be in 16..%d", width, height,
                         CDEM_RENDER_MAX_SIZE);
    if (n_panels < 1 || !panels)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "plot: %s: no panel to draw", path);
    for (size_t i = 0; i < n_panels; i++)
        CDEM_TRY(check_panel(&panels[i], err));
    cdem_render_target t;
    CDEM_TRY(cdem_render_target_open(&t, path, fmt, width, height, "plot", err));
    cairo_t *cr = cairo_create(t.surf);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cdem_status st = CDEM_OK;
    double pw = (double)width / n_panels;
    for (size_t i = 0; i < n_panels && st == CDEM_OK; i++)
        st = cdem_plot_draw(cr, &panels[i], i * pw, 0, pw, height, NULL, err);
    cairo_destroy(cr);
    return cdem_render_target_close(&t, st, err);
}
