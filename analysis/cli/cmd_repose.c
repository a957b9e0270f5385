/* cmd_repose: `cdem-strain repose`; its help (below) says what it does. */
#include "cmd_plot.h"
#include "cmd_support.h"
#include "commands.h"
#include "render.h"
#include "repose.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const repose_forms[] = {
    "RUN.h5 [--increment K|last|equil|first] [-o OUT.png|.pdf|.svg] [--width N] [--height N]",
    NULL};
static const cdem_cli_option repose_options[] = {
    {"--increment", "K|last|equil|first", "the increment (default last)"},
    {"-o, --output", "OUT.png|.pdf|.svg", "the free surface with the fitted flanks"},
    CDEM_PLOT_WIDTH_OPTION,
    CDEM_PLOT_HEIGHT_OPTION,
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain repose",
    .forms = repose_forms,
    .about = "Angle of repose: the slope of the free surface of a repose-collapse run, fitted "
             "on each flank (docs/rendering.md, \"cdem-strain repose\").",
    .options = repose_options,
};

static cdem_status repose_figure(const cdem_plot_args *a, const cdem_state *s, int number,
                                 const cdem_repose_result *res, cdem_error *err) {
    cdem_render_format fmt;
    CDEM_TRY(cdem_render_format_from_path(a->out, &fmt, err));
    cdem_render_options o;
    cdem_render_options_default(&o);
    o.width = a->width ? a->width : 1200;
    o.height = a->height;
    char label[160];
    snprintf(label, sizeof label, "Increment %d   Angle of repose %.1f deg", number,
             res->angle_deg);
    cdem_render_scene sc = {.state = s, .label = label};
    int h = o.height;
    if (!h)
        CDEM_TRY(cdem_render_auto_height(&sc, &o, &h, err));
    cdem_render_layout lay;
    CDEM_TRY(cdem_render_layout_compute(&sc, &o, o.width, h, &lay, err));
    cdem_render_target t;
    CDEM_TRY(cdem_render_target_open(&t, a->out, fmt, o.width, h, a->cmd, err));
    cairo_t *cr = cairo_create(t.surf);
    cdem_status st = cdem_render_draw(cr, o.width, h, &sc, &o, err);
    for (int side = 0; side < 2 && st == CDEM_OK; side++) {
        /* each fitted flank's line, extended by one column at both ends */
        const cdem_repose_flank *f = &res->flank[side];
        if (f->n < 2)
            continue;
        double x0 = f->x_first - res->column_width, x1 = f->x_last + res->column_width;
        double d0x, d0y, d1x, d1y;
        cdem_render_layout_to_device(&lay, x0, f->intercept + f->slope * x0, &d0x, &d0y);
        cdem_render_layout_to_device(&lay, x1, f->intercept + f->slope * x1, &d1x, &d1y);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_line_width(cr, fmax(2.0, o.width / 400.0));
        cairo_move_to(cr, d0x, d0y);
        cairo_line_to(cr, d1x, d1y);
        cairo_stroke(cr);
    }
    cairo_destroy(cr);
    return cdem_render_target_close(&t, st, err);
}

int cdem_cmd_plot_repose(int argc, char **argv) {
    cdem_plot_args a = {.cmd = "repose", .help = &help};
    int rc = cdem_cmd_plot_parse_one(argc, argv, &a);
    if (rc)
        return rc;
    cdem_error err;
    cdem_render_format fmt;
    if (a.out && cdem_render_format_from_path(a.out, &fmt, &err) != CDEM_OK)
        return cdem_cmd_fail(a.cmd, NULL, &err);
    cdem_h5_reader *r;
    cdem_state s = {0};
    cdem_increment_info info;
    cdem_repose_result res;
    cdem_status st = cdem_cmd_plot_open_increment(&a, &r, &s, &info, &err);
    cdem_params prm;
    if (st == CDEM_OK && cdem_h5_reader_params(r, &prm, &err) == CDEM_OK &&
        prm.mode != CDEM_MODE_REPOSE)
        fprintf(stderr, "cdem-strain repose: note: %s is a '%s' run, not a repose-collapse run\n",
                a.files[0], cdem_mode_name(prm.mode));
    if (st == CDEM_OK)
        st = cdem_repose_measure(&s, &res, &err);
    if (st == CDEM_OK) {
        printf("angle of repose = %.2f deg (increment %d, %zu surface elements fitted, columns "
               "%.4g m wide)\n",
               res.angle_deg, (int)info.number, res.n_fitted, res.column_width);
        for (int side = 0; side < 2; side++)
            if (res.flank[side].n >= 2)
                printf("  %s flank: %.2f deg, %zu elements, x %.4g .. %.4g m, rms misfit %.4g m\n",
                       side ? "right" : "left", res.flank[side].angle_deg, res.flank[side].n,
                       res.flank[side].x_first, res.flank[side].x_last,
                       res.flank[side].residual_rms);
    }
    if (st == CDEM_OK && a.out)
        st = repose_figure(&a, &s, (int)info.number, &res, &err);
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
    return st == CDEM_OK ? 0 : cdem_cmd_fail(a.cmd, a.files[0], &err);
}

const cdem_command cdem_command_repose = {"repose", "angle of repose of the free surface", &help,
                                          cdem_cmd_plot_repose};
