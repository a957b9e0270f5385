/* cmd_plot_series: `cdem-strain plot-series`; its help (below) says what it does. */
#include "cmd_plot.h"
#include "cmd_support.h"
#include "commands.h"
#include "plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const series_forms[] = {
    "RUN.h5 [RUN2.h5 ...] --y COLUMN [--x COLUMN] -o OUT.png|.pdf|.svg "
    "[--xrange MIN,MAX] [--yrange MIN,MAX] [--width N] [--height N]",
    NULL};
/* the picture size options shared by the plots */
#define CDEM_PLOT_WIDTH_OPTION                                                                     \
    { "--width", "N", "pixels (PNG) or points (PDF, SVG), 16 to 20000" }
#define CDEM_PLOT_HEIGHT_OPTION                                                                    \
    { "--height", "N", "as --width" }
static const cdem_cli_option series_options[] = {
    {"--y", "COLUMN",
     "the /series column to plot: time, step, kinetic_energy, contacts, bonds, n_elements, "
     "net_displacement, boundary_force_x, boundary_force_y, base_force_x, base_force_y, "
     "axial_strain, differential_stress, sea_level, left_wall_force_x, left_wall_force_y, "
     "right_wall_force_x, right_wall_force_y, salt_area, salt_top"},
    {"--x", "COLUMN",
     "the x axis, any column as for --y (default time; e.g. net_displacement, or "
     "axial_strain for a biaxial stress-strain curve)"},
    {"-o, --output", "OUT.png|.pdf|.svg", "the picture"},
    {"--xrange", "MIN,MAX", "fixed x range"},
    {"--yrange", "MIN,MAX", "fixed y range"},
    CDEM_PLOT_WIDTH_OPTION,
    CDEM_PLOT_HEIGHT_OPTION,
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain plot-series",
    .forms = series_forms,
    .about = "Line plot of a time-series column of one or more runs (one curve per run), e.g. "
             "kinetic_energy to check that equilibration has settled. Columns and units: "
             "docs/format.md, \"/series\".",
    .options = series_options,
};

int cdem_cmd_plot_series(int argc, char **argv) {
    cdem_plot_args a = {.cmd = "plot-series", .help = &help};
    int rc = cdem_cmd_plot_parse(argc, argv, &a);
    if (rc)
        return rc;
    if (!a.n_files)
        return cdem_cmd_usage(&help, "missing the run file (RUN.h5)");
    if (!a.y)
        return cdem_cmd_usage(&help, "missing --y COLUMN");
    if (!a.out)
        return cdem_cmd_usage(&help, "missing -o OUT.png|.pdf|.svg");
    /* any column can be the x axis (axial_strain for a biaxial stress-strain curve) */
    const char *xname = a.x ? a.x : "time";
    cdem_error err;
    const char *ylabel = NULL, *xlabel = NULL;
    if (cdem_cmd_plot_column(NULL, 0, xname, NULL, &xlabel, &err) != CDEM_OK)
        return cdem_cmd_usage(&help, err.msg);
    if (cdem_cmd_plot_column(NULL, 0, a.y, NULL, &ylabel, &err) != CDEM_OK)
        return cdem_cmd_fail(a.cmd, NULL, &err);
    cdem_plot_series ser[CDEM_PLOT_MAX_FILES];
    double *buf[CDEM_PLOT_MAX_FILES] = {0};
    memset(ser, 0, sizeof ser);
    cdem_status st = CDEM_OK;
    for (size_t i = 0; i < a.n_files && st == CDEM_OK; i++) {
        cdem_series_sample *smp = NULL;
        size_t n = 0;
        st = cdem_cmd_plot_read_series(a.files[i], &smp, &n, &err);
        if (st == CDEM_OK && n == 0)
            st = CDEM_FAIL(&err, CDEM_ERR_NOTFOUND, "%s has no time-series samples", a.files[i]);
        if (st == CDEM_OK && !(buf[i] = malloc(2 * n * sizeof(double))))
            st = CDEM_FAIL(&err, CDEM_ERR_NOMEM, "no memory for %zu samples", n);
        if (st == CDEM_OK) {
            cdem_cmd_plot_column(smp, n, xname, buf[i], NULL, &err);
            cdem_cmd_plot_column(smp, n, a.y, buf[i] + n, NULL, &err);
            ser[i] =
                (cdem_plot_series){.x = buf[i],
                                   .y = buf[i] + n,
                                   .n = n,
                                   .label = a.n_files > 1 ? cdem_cmd_base_name(a.files[i]) : NULL,
                                   .line = 1};
        }
        free(smp);
    }
    if (st == CDEM_OK) {
        cdem_plot p = {.title = a.n_files == 1 ? cdem_cmd_base_name(a.files[0]) : NULL,
                       .xlabel = xlabel,
                       .ylabel = ylabel,
                       .series = ser,
                       .n_series = a.n_files,
                       .fix_x = a.fix_x,
                       .xmin = a.range[0],
                       .xmax = a.range[1],
                       .fix_y = a.fix_y,
                       .ymin = a.range[2],
                       .ymax = a.range[3]};
        st = cdem_plot_to_file(a.out, &p, 1, a.width ? a.width : 1000, a.height ? a.height : 600,
                               &err);
    }
    for (size_t i = 0; i < a.n_files; i++)
        free(buf[i]);
    return st == CDEM_OK ? 0 : cdem_cmd_fail(a.cmd, NULL, &err);
}

const cdem_command cdem_command_plot_series = {"plot-series", "line plot of time-series columns",
                                               &help, cdem_cmd_plot_series};
