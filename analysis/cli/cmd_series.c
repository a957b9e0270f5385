/* cmd_series: `cdem-strain series`; its help (below) says what it does. */
#include "cmd_options.h"

#include "cmd_plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int cmd_series(const cdem_cmd_options *o) {
    if (!o->file)
        return cdem_cmd_usage(o->help, "missing the run file (RUN.h5)");
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(o->file, &r, &err) != CDEM_OK)
        return cdem_cmd_fail(NULL, NULL, &err);
    cdem_series_sample *smp = NULL;
    size_t n = 0;
    double *cols = NULL;
    const size_t nc = cdem_cmd_series_column_count();
    cdem_status st = cdem_h5_reader_read_series(r, &smp, &n, &err);
    cdem_h5_reader_close(r);
    if (st == CDEM_OK && !(cols = malloc((n ? n : 1) * nc * sizeof *cols)))
        st = CDEM_FAIL(&err, CDEM_ERR_NOMEM, "out of memory for %zu samples", n);
    for (size_t c = 0; c < nc && st == CDEM_OK; c++)
        st = cdem_cmd_plot_column(smp, n, cdem_cmd_series_column_name(c), cols + c * n, NULL, &err);
    cdem_cmd_output out; /* -o OUT: written to OUT.tmp, renamed on success */
    if (st == CDEM_OK)
        st = cdem_cmd_output_open(&out, o->out, &err);
    if (st == CDEM_OK) {
        FILE *f = out.f;
        for (size_t c = 0; c < nc; c++)
            fprintf(f, "%s%s", c ? "," : "", cdem_cmd_series_column_name(c));
        fputc('\n', f);
        for (size_t k = 0; k < n; k++)
            for (size_t c = 0; c < nc; c++) {
                const double v = cols[c * n + k];
                if (isfinite(v))
                    fprintf(f, "%s%.17g", c ? "," : "", v);
                else
                    fprintf(f, "%snan", c ? "," : "");
                if (c + 1 == nc)
                    fputc('\n', f);
            }
        st = cdem_cmd_output_close(&out, st, &err);
    }
    free(cols);
    free(smp);
    return st == CDEM_OK ? CDEM_EXIT_OK : cdem_cmd_fail(NULL, NULL, &err);
}

static const char *const series_forms[] = {"RUN.h5 [-o OUT.csv]", NULL};
static const cdem_cli_option series_options[] = {
    {"-o, --output", "OUT.csv", "output file (default: standard output)"}, {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain series",
    .forms = series_forms,
    .about = "The run's whole time series (/series) as CSV: a header of the column names (step, "
             "time, kinetic_energy, contacts, bonds, n_elements, net_displacement, "
             "boundary_force_x, boundary_force_y, base_force_x, base_force_y, axial_strain, "
             "differential_stress, sea_level, left_wall_force_x, left_wall_force_y, "
             "right_wall_force_x, right_wall_force_y, salt_area, salt_top; units in "
             "docs/format.md), then one line per sample, full precision, nan for sea_level "
             "without sedimentation, for salt_area and salt_top without salt, and for the "
             "columns a file's writer did not yet measure (files written before them).",
    .options = series_options,
};

CDEM_SIMPLE_COMMAND(series, "series", "the time series as CSV", 1, cmd_series);
