/* cmd_voids: `cdem-strain voids`; its help (below) says what it does. */
#include "cmd_plot.h"
#include "cmd_support.h"
#include "commands.h"
#include "voids.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const voids_forms[] = {"RUN.h5 [--increment K|last|equil|first] [--window M]",
                                          NULL};
static const cdem_cli_option voids_options[] = {
    {"--increment", "K|last|equil|first", "the increment (default last)"},
    {"--window", "M",
     "horizontal span of the steepest-slope measure in m (default 1000; at least the largest "
     "element's diameter)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain voids",
    .forms = voids_forms,
    .about = "Open space a rock mass should not hold, in one increment: the steepest surface "
             "slope over a horizontal window (cliffs, chasm walls), voids (closed-off room for "
             "the largest element: cavities under arches, gaps behind rigid blocks) and the "
             "deepest open fissure (analysis/measure/voids.h, docs/analysis.md).",
    .options = voids_options,
};

int cdem_cmd_plot_voids(int argc, char **argv) {
    cdem_plot_args a = {.cmd = "voids", .help = &help};
    int rc = cdem_cmd_plot_parse_one(argc, argv, &a);
    if (rc)
        return rc;
    cdem_error err;
    cdem_h5_reader *r;
    cdem_state s = {0};
    cdem_increment_info info;
    cdem_voids_result res;
    cdem_status st = cdem_cmd_plot_open_increment(&a, &r, &s, &info, &err);
    if (st == CDEM_OK) {
        st = cdem_voids_measure(&s, a.window > 0.0 ? a.window : 1000.0, &res, &err);
        if (st != CDEM_OK) /* the measure's message, with the run it was asked of */
            cdem_error_prefix(&err, "%s, increment %d", a.files[0], (int)info.number);
    }
    if (st == CDEM_OK) {
        printf("increment %d\n", (int)info.number);
        if (res.steepest_x1 > res.steepest_x0)
            printf("steepest surface slope = %.2f deg over %.4g m (from x = %.6g to %.6g m)\n",
                   res.steepest_deg, res.window, res.steepest_x0, res.steepest_x1);
        else /* measure.py and the examples read the number: it stays */
            printf("steepest surface slope = 0.00 deg over %.4g m (none measured: the free "
                   "elements' surface is not a window and a column long)\n",
                   res.window);
        printf("voids = %zu (closed-off room for the largest element, radius %.4g m), their room "
               "%.4g m^2\n",
               res.n_voids, res.min_clearance, res.void_area);
        printf("largest clearance inside = %.4g m (%.2f x the largest radius) at x = %.6g m, y = "
               "%.6g m\n",
               res.largest_clearance, res.largest_clearance / res.min_clearance, res.largest_x,
               res.largest_y);
        printf("deepest open fissure = %.4g m (below the rims within %.4g m on either side) at x "
               "= %.6g m, bottom y = %.6g m\n",
               res.fissure_depth, res.fissure_width, res.fissure_x, res.fissure_y);
    }
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
    return st == CDEM_OK ? 0 : cdem_cmd_fail(a.cmd, NULL, &err);
}

const cdem_command cdem_command_voids = {
    "voids", "steepest surface slope, voids and open fissures (cliffs, chasms, cavities)", &help,
    cdem_cmd_plot_voids};
