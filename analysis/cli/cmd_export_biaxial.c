/* cmd_export_biaxial: `cdem-strain export-biaxial`; its help (below) says what it does. */
#include "cmd_options.h"

#include "analysis.h"
#include "biaxial.h"

#include <stdio.h>
#include <stdlib.h>

static int cmd_export_biaxial(const cdem_cmd_options *o) {
    if (!o->out)
        return cdem_cmd_usage(o->help, "export-biaxial needs -o OUT.txt");
    cdem_analysis *a;
    int rc = cdem_cmd_open_run(o, &a);
    if (rc)
        return rc;
    cdem_error err;
    cdem_series_sample *smp = NULL;
    size_t n = 0;
    cdem_status st = CDEM_OK;
    if (cdem_analysis_params(a)->mode != CDEM_MODE_BIAXIAL)
        st = CDEM_FAIL(&err, CDEM_ERR_INVALID,
                       "%s is a '%s' run; export-biaxial needs a biaxial test run", o->file,
                       cdem_mode_name(cdem_analysis_params(a)->mode));
    if (st == CDEM_OK)
        st = cdem_h5_reader_read_series(cdem_analysis_reader(a), &smp, &n, &err);
    if (st == CDEM_OK)
        st = cdem_biaxial_write(o->out, smp, n, &err);
    free(smp);
    cdem_analysis_close(a);
    return st == CDEM_OK ? CDEM_EXIT_OK : cdem_cmd_fail(NULL, NULL, &err);
}

static const char *const biaxial_forms[] = {"RUN.h5 -o OUT.txt", NULL};
static const cdem_cli_option biaxial_options[] = {{"-o, --output", "OUT.txt", "output file"},
                                                  {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain export-biaxial",
    .forms = biaxial_forms,
    .about = "The time series of a biaxial test as text: time step, axial strain, differential "
             "stress (N/m) (docs/formats-text.md).",
    .options = biaxial_options,
};

CDEM_SIMPLE_COMMAND(export_biaxial, "export-biaxial",
                    "biaxial test series: time step, axial strain, differential stress", 1,
                    cmd_export_biaxial);
