/* cmd_wedge: the wedge subcommand of cdem-strain:
 *   wedge RUN.h5 [-o OUT.csv] [--increment K|last|all] [--threshold M]
 *       accretionary-wedge measurements per increment (measure/wedge.h, docs/analysis.md
 *       "Wedge"): a CSV table, and the last increment's summary on standard error. */
#include "analysis.h"
#include "cmd_support.h"
#include "commands.h"
#include "run_file.h"
#include "wedge.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const wedge_forms[] = {
    "RUN.h5 [-o OUT.csv] [--increment K|last|all] [--threshold M]", NULL};
static const cdem_cli_option wedge_options[] = {
    {"-o, --output", "OUT.csv", "output file (default: standard output)"},
    {"--increment", "K|last|equil|all",
     "one increment, or all (default) from the end of "
     "equilibration on"},
    {"--threshold", "M", "deformed-zone threshold in m (default: the mean element diameter)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain wedge",
    .forms = wedge_forms,
    .about = "Accretionary-wedge measurements per increment from the end of equilibration, as "
             "CSV: shortening, height, length, taper, area change and the forces on the moving "
             "wall, the base and each lateral wall (columns and definitions in "
             "docs/analysis.md, \"Wedge\").",
    .options = wedge_options,
};

static int run(int argc, char **argv) {
    const char *cmd = "wedge", *file = NULL, *out = NULL, *inc = "all";
    cdem_wedge_options opt = {0};
    for (int i = 1; i < argc; i++) {
        const cdem_cli_option *o;
        const char *val;
        const cdem_cmd_arg kind = cdem_cmd_next_arg(&help, argc, argv, &i, &o, &val);
        if (kind == CDEM_CMD_ARG_USAGE)
            return CDEM_EXIT_USAGE;
        if (kind == CDEM_CMD_ARG_POSITIONAL && file)
            return cdem_cmd_usage(&help, "need exactly one run file (RUN.h5)");
        if (kind == CDEM_CMD_ARG_POSITIONAL)
            file = argv[i];
        else if (cdem_cli_option_is(o, "--output"))
            out = val;
        else if (cdem_cli_option_is(o, "--increment"))
            inc = val;
        else if (!cdem_cmd_parse_number(val, &opt.threshold) || opt.threshold < 0) /* --threshold */
            return cdem_cmd_usage(&help, "--threshold must be a length in m >= 0 (0 = default)");
    }
    if (!file)
        return cdem_cmd_usage(&help, "missing the run file (RUN.h5)");
    cdem_error err;
    cdem_analysis *a;
    if (cdem_analysis_open(file, &a, &err) != CDEM_OK)
        return cdem_cmd_fail(cmd, NULL, &err);
    size_t first = 0, last = cdem_analysis_count(a) - 1;
    cdem_status st = CDEM_OK;
    if (strcmp(inc, "all") != 0) {
        st = cdem_analysis_find(a, inc, &first, &err);
        last = first;
    }
    if (cdem_analysis_params(a)->mode == CDEM_MODE_DETACHMENT &&
        cdem_analysis_params(a)->detachment_walls == CDEM_WALLS_BOTH)
        fprintf(stderr,
                "cdem-strain wedge: note: %s moves both walls: the wedge is measured from "
                "the right wall; wall_force_* is the sum over both walls (their x components "
                "cancel), left_wall_force_* and right_wall_force_* give each wall's push\n",
                file);
    cdem_wedge_row *rows = NULL;
    size_t n = 0;
    cdem_wedge_ref ref;
    if (st == CDEM_OK)
        st = cdem_wedge_analyse(a, &opt, first, last, &rows, &n, &ref, &err);
    if (st == CDEM_OK) {
        cdem_cmd_output output;
        st = cdem_cmd_output_open(&output, out, &err);
        if (st == CDEM_OK)
            st =
                cdem_cmd_output_close(&output, cdem_wedge_write_csv(output.f, rows, n, &err), &err);
    }
    if (st == CDEM_OK && n > 0) {
        const cdem_wedge_row *r = &rows[n - 1];
        fprintf(stderr,
                "cdem-strain wedge: reference increment %d: length %.6g m, thickness %.6g m, "
                "columns %.4g m, threshold %.4g m\n"
                "cdem-strain wedge: increment %d: shortening %.6g m (%.3g %%), height %.6g m, "
                "length %.6g m, taper %.3g deg, area change %.3g %%\n",
                (int)cdem_analysis_info(a, cdem_analysis_equil_index(a))->number, ref.length0,
                ref.thickness0, ref.column_width, ref.threshold, r->number, r->shortening,
                r->shortening_percent, r->height, r->length, r->taper_deg, r->area_change_percent);
    }
    free(rows);
    cdem_analysis_close(a);
    return st == CDEM_OK ? 0 : cdem_cmd_fail(cmd, file, &err);
}

const cdem_command cdem_command_wedge = {
    "wedge", "accretionary-wedge height, length, taper, area, forces", &help, run};
