/* cmd_faults: the faults subcommand of cdem-strain:
 *   faults RUN.h5 [--increment K|last|equil|first] [--quantity NAME] [--threshold V]
 *                 [--bin M] [--min-rows N] [--include-salt] [-o OUT.csv]
 *       fault zones picked from a strain field (measure/faults.h): one CSV row per zone
 *       with where it reaches up and down, its dip and dip direction; a summary on stderr. */
#include "analysis.h"
#include "cmd_support.h"
#include "commands.h"
#include "faults.h"
#include "quantity.h"
#include "run_file.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static const char synopsis[] = "RUN.h5 [--increment K|last|equil|first] [--quantity NAME] "
                               "[--threshold V] [--bin M] [--min-rows N] [--include-salt] "
                               "[-o OUT.csv]";
static const char *const forms[] = {synopsis, NULL};
static const cdem_cli_option options[] = {
    {"--increment", "K|last|equil|first", "the increment (default last)"},
    {"--quantity", "NAME", "the strain field (default total-max-shear; any quantity)"},
    {"--threshold", "V",
     "value at or above which a cell is in a fault zone (default: the field's outlier bound, "
     "median + 3 x 1.4826 x MAD of the cells)"},
    {"--bin", "M", "cell size in m (default 2 x the largest free radius)"},
    {"--min-rows", "N", "cells of height a zone must span, >= 2 (default 4)"},
    {"--include-salt", NULL,
     "count the salt's elements too (default: the cover's only; a salt's strain is flow, "
     "not faulting)"},
    {"-o, --output", "OUT.csv", "output file (default: standard output)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain faults",
    .forms = forms,
    .about =
        "Fault zones picked from a strain field: the free elements' values are binned on "
        "a square grid, runs of cells at or above the threshold in each row are linked "
        "from the top down into zones, and a line through each zone gives its dip and "
        "dip direction (analysis/measure/faults.h, docs/analysis.md \"Fault zones\"). CSV, one row "
        "per zone ordered by x at its top: zone, x_top, y_top, x_bottom, y_bottom (m), "
        "dip (degrees), dips (left or right), rows, mean and max value. A summary line "
        "goes to standard error.",
    .options = options,
    .notes = "A thrust verges away from its dip direction: with the right wall pushing, "
             "forward-verging thrusts dip right.",
};

static cdem_status write_csv(FILE *f, const cdem_faults_result *r, cdem_error *err) {
    fprintf(f, "zone,x_top,y_top,x_bottom,y_bottom,dip,dips,rows,mean,max\n");
    for (size_t k = 0; k < r->n; k++) {
        const cdem_fault_zone *z = &r->zone[k];
        fprintf(f, "%zu,%.6g,%.6g,%.6g,%.6g,%.2f,%s,%d,%.4g,%.4g\n", k + 1, z->x_top, z->y_top,
                z->x_bottom, z->y_bottom, z->dip_deg, z->dips_right ? "right" : "left", z->rows,
                z->mean_value, z->max_value);
    }
    if (ferror(f))
        return CDEM_FAIL(err, CDEM_ERR_IO, "error writing the CSV");
    return CDEM_OK;
}

static int run(int argc, char **argv) {
    const char *file = NULL, *out = NULL, *inc = "last", *qname = "total-max-shear";
    cdem_faults_options o;
    cdem_faults_default_options(&o);
    for (int i = 1; i < argc; i++) {
        const cdem_cli_option *opt;
        const char *val;
        const cdem_cmd_arg kind = cdem_cmd_next_arg(&help, argc, argv, &i, &opt, &val);
        if (kind == CDEM_CMD_ARG_USAGE)
            return CDEM_EXIT_USAGE;
        if (kind == CDEM_CMD_ARG_POSITIONAL) {
            if (file)
                return cdem_cmd_usage(&help, "need exactly one run file (RUN.h5)");
            file = argv[i];
            continue;
        }
        double x;
        if (cdem_cli_option_is(opt, "--increment"))
            inc = val;
        else if (cdem_cli_option_is(opt, "--quantity"))
            qname = val;
        else if (cdem_cli_option_is(opt, "--output"))
            out = val;
        else if (cdem_cli_option_is(opt, "--threshold")) {
            if (!cdem_cmd_parse_number(val, &x) || !(x > 0.0))
                return cdem_cmd_usage(&help, "--threshold must be a number > 0");
            o.threshold = x;
        } else if (cdem_cli_option_is(opt, "--bin")) {
            if (!cdem_cmd_parse_number(val, &x) || !(x > 0.0))
                return cdem_cmd_usage(&help, "--bin must be a length in m > 0");
            o.bin = x;
        } else if (cdem_cli_option_is(opt, "--min-rows")) {
            if (!cdem_cmd_parse_number(val, &x) || x < 2 || x > 100000 || x != floor(x))
                return cdem_cmd_usage(&help, "--min-rows must be a whole number >= 2");
            o.min_rows = (int)x;
        } else if (cdem_cli_option_is(opt, "--include-salt"))
            o.include_salt = 1;
    }
    if (!file)
        return cdem_cmd_usage(&help, "missing the run file (RUN.h5)");
    cdem_error err;
    const cdem_quantity *q;
    if (cdem_quantity_find(qname, &q, &err) != CDEM_OK)
        return cdem_cmd_fail("faults", NULL, &err);
    cdem_analysis *a;
    if (cdem_analysis_open(file, &a, &err) != CDEM_OK)
        return cdem_cmd_fail("faults", NULL, &err);
    size_t index = 0;
    const cdem_state *s = NULL;
    double *v = NULL;
    cdem_faults_result res = {0};
    cdem_status st = cdem_analysis_find(a, inc, &index, &err);
    if (st == CDEM_OK)
        st = cdem_analysis_values(a, index, q, &s, &v, &err);
    if (st == CDEM_OK)
        st = cdem_faults_pick(s, v, &o, &res, &err);
    if (st == CDEM_OK) {
        cdem_cmd_output output;
        st = cdem_cmd_output_open(&output, out, &err);
        if (st == CDEM_OK)
            st = cdem_cmd_output_close(&output, write_csv(output.f, &res, &err), &err);
    }
    if (st == CDEM_OK) {
        size_t left = 0;
        for (size_t k = 0; k < res.n; k++)
            left += !res.zone[k].dips_right;
        fprintf(stderr,
                "cdem-strain faults: increment %d: %zu zones (%zu dip left, %zu dip right) of %s "
                ">= %.4g%s on cells of %.4g m\n",
                (int)cdem_analysis_info(a, index)->number, res.n, left, res.n - left, q->name,
                res.threshold, o.threshold > 0.0 ? "" : " (median + 3 robust sd)", res.bin);
    }
    cdem_faults_free(&res);
    free(v);
    cdem_analysis_close(a);
    return st == CDEM_OK ? 0 : cdem_cmd_fail("faults", file, &err);
}

const cdem_command cdem_command_faults = {
    "faults", "fault zones from a strain field: position, dip and dip direction", &help, run};
