/* render_style: the drawing options of render.h that are plain values: the defaults (the
 * original program's colours and toggles), colours as text (#RRGGBB) both ways, the options
 * as a listing, and the output format from a file name. Kept apart from render.c, which
 * draws. */
#include "render.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

static cdem_rgba rgb(double r, double g, double b) {
    cdem_rgba c = {r, g, b, 1.0};
    return c;
}

void cdem_render_options_default(cdem_render_options *o) {
    memset(o, 0, sizeof *o);
    o->width = 1200;
    o->height = 0;
    o->margin = 0.02;
    o->pregrowth_layers = 24;
    o->band_layers = 1;
    o->growth1_layers = 10;
    o->show_fill = 1;
    o->show_outline = 1;
    o->show_colours = 1;
    o->show_vectors = 1;
    o->show_axes = 1;
    o->show_scale_bar = 1;
    o->show_colour_bar = 1;
    o->show_label = 1;
    o->font_size = 0.0;
    o->outline_width = 0.5;
    o->line_width = 1.0;
    o->weak_alpha = 0.45;
    o->background = rgb(1.0, 1.0, 1.0);
    o->wall = rgb(0.545, 0.353, 0.169);    /* #8b5a2b brown */
    o->pregrowth[0] = rgb(1.0, 0.85, 0.0); /* #ffd900 yellow */
    o->pregrowth[1] = rgb(0.85, 0.1, 0.1); /* #d91a1a red */
    o->growth1[0] = rgb(1.0, 0.95, 0.6);   /* #fff299 pale yellow */
    o->growth1[1] = rgb(0.85, 0.0, 0.85);  /* #d900d9 magenta */
    o->growth2[0] = rgb(0.75, 0.95, 1.0);  /* #bff2ff pale cyan */
    o->growth2[1] = rgb(0.1, 0.35, 0.85);  /* #1a59d9 blue */
    o->salt[0] = rgb(0.784, 0.635, 0.910); /* #c8a2e8 lilac */
    o->salt[1] = rgb(0.655, 0.498, 0.820); /* #a77fd1 darker lilac */
    o->highlight = rgb(0.2, 0.2, 0.2);     /* #333333 dark grey */
    o->biaxial_edge = rgb(0.0, 0.7, 0.0);  /* #00b300 green */
    o->footwall = rgb(0.8, 0.8, 0.8);      /* #cccccc light grey */
    o->undefined = rgb(0.6, 0.6, 0.6);     /* #999999 neutral grey */
    o->outline = rgb(0.25, 0.25, 0.25);    /* #404040 */
    o->outline.a = 0.6;
    o->vector = rgb(0.0, 0.0, 0.0);  /* black */
    o->axis[0] = rgb(0.0, 0.0, 0.0); /* black */
    o->axis[1] = rgb(1.0, 1.0, 1.0); /* white */
    o->text = rgb(0.0, 0.0, 0.0);    /* black */
}

static unsigned colour_byte(double v) {
    if (!(v > 0))
        return 0;
    if (v >= 1)
        return 255;
    return (unsigned)lround(v * 255.0);
}

void cdem_render_format_colour(const cdem_rgba *c, char buf[10]) {
    snprintf(buf, 10, "#%02x%02x%02x%02x", colour_byte(c->r), colour_byte(c->g), colour_byte(c->b),
             colour_byte(c->a));
}

void cdem_render_options_view(const cdem_render_options *o, FILE *f) {
    static const char *const colour_names[] = {
        "background", "wall",         "pregrowth_0", "pregrowth_1", "growth1_0",
        "growth1_1",  "growth2_0",    "growth2_1",   "salt_0",      "salt_1",
        "highlight",  "biaxial_edge", "footwall",    "undefined",   "outline",
        "vector",     "axis_0",       "axis_1",      "text"};
    const cdem_rgba *cols[] = {&o->background, &o->wall,       &o->pregrowth[0], &o->pregrowth[1],
                               &o->growth1[0], &o->growth1[1], &o->growth2[0],   &o->growth2[1],
                               &o->salt[0],    &o->salt[1],    &o->highlight,    &o->biaxial_edge,
                               &o->footwall,   &o->undefined,  &o->outline,      &o->vector,
                               &o->axis[0],    &o->axis[1],    &o->text};
    fprintf(f, "render.width = %d\n", o->width);
    fprintf(f, "render.height = %d%s\n", o->height, o->height == 0 ? " (automatic)" : "");
    if (o->has_zoom)
        fprintf(f, "render.zoom = %.9g %.9g %.9g %.9g (m: xmin xmax ymin ymax)\n", o->zoom_xmin,
                o->zoom_xmax, o->zoom_ymin, o->zoom_ymax);
    else
        fprintf(f, "render.zoom = fit all elements, margin %g\n", o->margin);
    fprintf(f, "render.pregrowth_layers = %d\n", o->pregrowth_layers);
    fprintf(f, "render.band_layers = %d\n", o->band_layers);
    fprintf(f, "render.growth1_layers = %d\n", o->growth1_layers);
    if (o->highlight_first > 0)
        fprintf(f, "render.highlight = %d..%d\n", o->highlight_first, o->highlight_last);
    else
        fprintf(f, "render.highlight = none\n");
    fprintf(f,
            "render.show = fill %d, outline %d, colours %d, vectors %d, axes %d, scale_bar %d, "
            "colour_bar %d, label %d\n",
            o->show_fill, o->show_outline, o->show_colours, o->show_vectors, o->show_axes,
            o->show_scale_bar, o->show_colour_bar, o->show_label);
    fprintf(f, "render.colour_bar_space = %d\n", o->colour_bar_space);
    fprintf(f, "render.font_size = %g%s\n", o->font_size, o->font_size <= 0 ? " (automatic)" : "");
    fprintf(f, "render.outline_width = %g\n", o->outline_width);
    fprintf(f, "render.line_width = %g\n", o->line_width);
    fprintf(f, "render.weak_alpha = %g\n", o->weak_alpha);
    for (size_t k = 0; k < sizeof cols / sizeof cols[0]; k++) {
        char buf[10];
        cdem_render_format_colour(cols[k], buf);
        fprintf(f, "render.colour.%s = %s\n", colour_names[k], buf);
    }
}

static int hex_digit(int c) {
    if (c >= '0' && c <= '9')
        return c - '0';
    c = tolower(c);
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    return -1;
}

cdem_status cdem_render_parse_colour(const char *text, cdem_rgba *out, cdem_error *err) {
    size_t len = text ? strlen(text) : 0;
    if (!text || text[0] != '#' || (len != 7 && len != 9))
        return CDEM_FAIL(err, CDEM_ERR_PARSE,
                         "colour '%s' is not valid: use \"#rrggbb\" or \"#rrggbbaa\" "
                         "(hexadecimal, e.g. \"#8b5a2b\")",
                         text ? text : "(null)");
    double ch[4] = {0, 0, 0, 1.0};
    for (size_t k = 0; k < (len - 1) / 2; k++) {
        int hi = hex_digit((unsigned char)text[1 + 2 * k]);
        int lo = hex_digit((unsigned char)text[2 + 2 * k]);
        if (hi < 0 || lo < 0)
            return CDEM_FAIL(err, CDEM_ERR_PARSE,
                             "colour '%s' is not valid: '%c%c' is not a hexadecimal byte "
                             "(use \"#rrggbb\" or \"#rrggbbaa\")",
                             text, text[1 + 2 * k], text[2 + 2 * k]);
        ch[k] = (hi * 16 + lo) / 255.0;
    }
    out->r = ch[0];
    out->g = ch[1];
    out->b = ch[2];
    out->a = ch[3];
    return CDEM_OK;
}

cdem_status cdem_render_format_from_path(const char *path, cdem_render_format *fmt,
                                         cdem_error *err) {
    const char *dot = path ? strrchr(path, '.') : NULL;
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (dot && (!slash || dot > slash)) {
        if (strcasecmp(dot, ".png") == 0) {
            *fmt = CDEM_RENDER_PNG;
            return CDEM_OK;
        }
        if (strcasecmp(dot, ".pdf") == 0) {
            *fmt = CDEM_RENDER_PDF;
            return CDEM_OK;
        }
        if (strcasecmp(dot, ".svg") == 0) {
            *fmt = CDEM_RENDER_SVG;
            return CDEM_OK;
        }
    }
    return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                     "image file '%s': extension '%s' is not supported: use .png, .pdf or .svg "
                     "(animated GIF is written by the gif encoder)",
                     path ? path : "(null)", dot && (!slash || dot > slash) ? dot : "(none)");
}
