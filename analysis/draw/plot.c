/* plot: cairo line plots (see plot.h). */
#include "plot.h"

#include "render.h"

#include "outfile.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const cdem_rgba plot_palette[] = {
    {0.12, 0.47, 0.71, 1}, {0.84, 0.15, 0.16, 1}, {0.17, 0.63, 0.17, 1}, {1.00, 0.50, 0.05, 1},
    {0.58, 0.40, 0.74, 1}, {0.55, 0.34, 0.29, 1}, {0.89, 0.47, 0.76, 1}, {0.50, 0.50, 0.50, 1},
};
#define PALETTE_N (sizeof plot_palette / sizeof plot_palette[0])

cdem_rgba cdem_plot_palette(size_t i) {
    return plot_palette[i % PALETTE_N];
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

static cdem_rgba series_colour(const cdem_plot_series *s, size_t i) {
    return s->colour.a > 0 ? s->colour : cdem_plot_palette(i);
}

static void draw_series(cairo_t *cr, const cdem_plot_layout *lay, const cdem_plot_series *s,
                        size_t i) {
    cdem_rgba c = series_colour(s, i);
    set_rgba(cr, &c);
    double lw = fmax(1.0, lay->font_size / 7.0);
    cairo_set_line_width(cr, lw);
    if (s->dashed) {
        double d[2] = {4 * lw, 3 * lw};
        cairo_set_dash(cr, d, 2, 0);
    }
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

static void draw_legend(cairo_t *cr, const cdem_plot *p, const cdem_plot_layout *lay) {
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
    if (!n || p->no_legend)
        return;
    double row = 1.4 * fs, bw = wmax + 4.0 * fs, bh = n * row + 0.6 * fs;
    double bx = lay->plot_x + lay->plot_w - bw - 0.5 * fs, by = lay->plot_y + 0.5 * fs;
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_rectangle(cr, bx, by, bw, bh);
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
        cdem_rgba c = series_colour(s, i);
        set_rgba(cr, &c);
        cairo_set_line_width(cr, fmax(1.0, fs / 7.0));
        if (s->line || !s->markers) {
            double lw = fmax(1.0, fs / 7.0), d[2] = {4 * lw, 3 * lw};
            if (s->dashed)
                cairo_set_dash(cr, d, 2, 0);
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
