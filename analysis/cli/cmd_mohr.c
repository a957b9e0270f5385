/* cmd_mohr: `cdem-strain mohr`; its help (below) says what it does. The tests are read and
 * fitted by mohr.h; this file parses, prints and draws. */
#include "cmd_plot.h"
#include "cmd_support.h"
#include "commands.h"
#include "mohr.h"
#include "params.h"
#include "plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const mohr_forms[] = {
    "RUN1.h5 RUN2.h5 ... | --data FILE (columns: sigma3 q, N/m)  [-o OUT.png|.pdf|.svg] "
    "[--width N] [--height N]",
    NULL};
static const cdem_cli_option mohr_options[] = {
    {"--data", "FILE", "fit peaks measured elsewhere: a text file of columns sigma3 q (N/m)"},
    {"-o, --output", "OUT.png|.pdf|.svg",
     "stress-strain curves and Mohr circles with the fitted envelope"},
    CDEM_PLOT_WIDTH_OPTION,
    CDEM_PLOT_HEIGHT_OPTION,
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain mohr",
    .forms = mohr_forms,
    .about = "Mohr-Coulomb fit of biaxial tests: takes the peak differential stress of each "
             "run (sigma3 = its confining pressure) and prints the cohesion and friction "
             "angle with their standard errors (none with exactly two tests). Formulas: "
             "docs/rendering.md.",
    .options = mohr_options,
};

#define MOHR_CIRCLE_POINTS 181

/* The picture: the stress-strain curves of the runs (none with --data) and the Mohr circles
 * of the tests with the envelope. */
static cdem_status mohr_figure(const cdem_plot_args *a, const cdem_mohr_runs *d,
                               const cdem_mohr_fit *fit, cdem_error *err) {
    size_t nt = d->n, runs = a->n_files;
    cdem_plot_series ser[CDEM_PLOT_MAX_FILES + 2];
    cdem_plot_series circ[CDEM_PLOT_MAX_FILES + 2];
    char tags[CDEM_PLOT_MAX_FILES][32];
    memset(ser, 0, sizeof ser);
    memset(circ, 0, sizeof circ);
    for (size_t i = 0; i < runs; i++)
        ser[i] = (cdem_plot_series){.x = d->strain[i],
                                    .y = d->stress[i],
                                    .n = d->n_samples[i],
                                    .label = cdem_cmd_base_name(a->files[i]),
                                    .line = 1};
    size_t nc = nt < CDEM_PLOT_MAX_FILES ? nt : CDEM_PLOT_MAX_FILES;
    double *pts = malloc((2 * nc * MOHR_CIRCLE_POINTS + 4) * sizeof(double));
    if (!pts)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "no memory for the Mohr circles");
    double smax = 0;
    for (size_t i = 0; i < nc; i++) {
        double c = (d->sigma3[i] + 0.5 * d->q[i]) / 1e6, r = 0.5 * d->q[i] / 1e6;
        double *x = pts + 2 * i * MOHR_CIRCLE_POINTS, *y = x + MOHR_CIRCLE_POINTS;
        for (int k = 0; k < MOHR_CIRCLE_POINTS; k++) {
            double t = M_PI * k / (MOHR_CIRCLE_POINTS - 1);
            x[k] = c + r * cos(t);
            y[k] = r * sin(t);
        }
        smax = fmax(smax, c + r);
        snprintf(tags[i], sizeof tags[i], "%.3g MPa", d->sigma3[i] / 1e6);
        /* the circle of run i in its curve's style (no colour of its own), tagged with its
         * confining pressure */
        circ[i] =
            (cdem_plot_series){.x = x, .y = y, .n = MOHR_CIRCLE_POINTS, .line = 1, .tag = tags[i]};
    }
    double *ex = pts + 2 * nc * MOHR_CIRCLE_POINTS, *ey = ex + 2;
    ex[0] = 0;
    ex[1] = smax * 1.05;
    ey[0] = fit->cohesion / 1e6;
    ey[1] = ey[0] + ex[1] * tan(fit->friction);
    char elabel[128];
    snprintf(elabel, sizeof elabel, "C = %.3g MPa, phi = %.1f deg", fit->cohesion / 1e6,
             fit->friction * 180 / M_PI);
    circ[nc] = (cdem_plot_series){
        .x = ex, .y = ey, .n = 2, .line = 1, .dashed = 1, .label = elabel, .colour = {0, 0, 0, 1}};
    cdem_plot panels[2] = {
        {.title = "Biaxial tests",
         .xlabel = "Axial strain",
         .ylabel = "Differential stress (MPa)",
         .series = ser,
         .n_series = runs},
        {.title = "Mohr circles at peak stress, tagged with sigma3",
         .xlabel = "Normal stress (MPa)",
         .ylabel = "Shear stress (MPa)",
         .series = circ,
         .n_series = nc + 1,
         .equal_aspect = 1,
         .fix_x = 1,
         .xmin = 0,
         .xmax = smax * 1.05,
         .fix_y = 1,
         .ymin = 0,
         .ymax = fmax(ey[1], 0.6 * smax)},
    };
    size_t np = runs ? 2 : 1;
    cdem_status st =
        cdem_plot_to_file(a->out, runs ? panels : panels + 1, np,
                          a->width ? a->width : (int)(700 * np), a->height ? a->height : 560, err);
    free(pts);
    return st;
}

int cdem_cmd_plot_mohr(int argc, char **argv) {
    cdem_plot_args a = {.cmd = "mohr", .help = &help};
    int rc = cdem_cmd_plot_parse(argc, argv, &a);
    if (rc)
        return rc;
    if (a.data && a.n_files)
        return cdem_cmd_usage(&help, "give either run files or --data FILE, not both");
    if (!a.data && a.n_files < 2)
        return cdem_cmd_usage(&help, "need at least 2 biaxial runs (or --data FILE)");
    cdem_error err;
    cdem_mohr_runs d;
    memset(&d, 0, sizeof d);
    cdem_status st = a.data ? cdem_mohr_read_table(a.data, &d.sigma3, &d.q, &d.n, &err)
                            : cdem_mohr_read_runs(a.files, a.n_files, &d, &err);
    cdem_mohr_fit fit;
    if (st == CDEM_OK)
        st = cdem_mohr_fit_envelope(d.sigma3, d.q, d.n, &fit, &err);
    if (st == CDEM_OK) {
        for (size_t i = 0; i < d.n; i++)
            printf("test %zu: sigma3 = %.6g MPa, peak q = %.6g MPa, sigma1 = %.6g MPa\n", i + 1,
                   d.sigma3[i] / 1e6, d.q[i] / 1e6, (d.sigma3[i] + d.q[i]) / 1e6);
        if (isfinite(fit.cohesion_err))
            printf("cohesion = %.4g +- %.2g MPa, friction angle = %.2f +- %.2f deg\n",
                   fit.cohesion / 1e6, fit.cohesion_err / 1e6, fit.friction * 180 / M_PI,
                   fit.friction_err * 180 / M_PI);
        else
            printf("cohesion = %.4g +- n/a MPa, friction angle = %.2f +- n/a deg (2 tests: "
                   "exact fit, no uncertainty)\n",
                   fit.cohesion / 1e6, fit.friction * 180 / M_PI);
    }
    if (st == CDEM_OK && a.out)
        st = mohr_figure(&a, &d, &fit, &err);
    cdem_mohr_runs_free(&d);
    return st == CDEM_OK ? 0 : cdem_cmd_fail(a.cmd, NULL, &err);
}

/* mohr's picture of runs given by name, with the envelope fitted to all of them
 * (cdem-strain calibrate). */
cdem_status cdem_cmd_mohr_picture(const char *const *files, size_t n, const char *out,
                                  cdem_error *err) {
    if (n > CDEM_PLOT_MAX_FILES)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "%zu runs: at most %d at once", n,
                         CDEM_PLOT_MAX_FILES);
    cdem_plot_args a = {.cmd = "mohr", .help = &help, .n_files = n, .out = out};
    for (size_t i = 0; i < n; i++)
        a.files[i] = files[i];
    cdem_mohr_runs d;
    cdem_mohr_fit fit;
    cdem_status st = cdem_mohr_read_runs(files, n, &d, err);
    if (st == CDEM_OK)
        st = cdem_mohr_fit_envelope(d.sigma3, d.q, d.n, &fit, err);
    if (st == CDEM_OK)
        st = mohr_figure(&a, &d, &fit, err);
    cdem_mohr_runs_free(&d);
    return st;
}

const cdem_command cdem_command_mohr = {"mohr", "Mohr-Coulomb fit of biaxial tests", &help,
                                        cdem_cmd_plot_mohr};
