/* cmd_faults: see cmd_faults.h. */
#include "cmd_faults.h"

#include "analysis.h"
#include "run_file.h"
#include "faults.h"
#include "outfile.h"
#include "quantity.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char synopsis[] = "RUN.h5 [--increment K|last|equil|first] [--quantity NAME] "
                               "[--threshold V] [--bin M] [--min-rows N] [-o OUT.csv]";
static const char *const forms[] = {synopsis, NULL};
static const cdem_cli_option options[] = {
    {"--increment", "K|last|equil|first", "the increment (default last)"},
    {"--quantity", "NAME", "the strain field (default total-max-shear; any quantity)"},
    {"--threshold", "V", "value at or above which a cell is in a fault zone (default 1)"},
    {"--bin", "M", "cell size in m (default 2 x the largest free radius)"},
    {"--min-rows", "N", "cells of height a zone must span, >= 2 (default 4)"},
    {"-o, --output", "OUT.csv", "output file (default: standard output)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_faults_help = {
    .program = "cdem-strain faults",
    .forms = forms,
    .about = "Fault zones picked from a strain field: the free elements' values are binned on "
             "a square grid, runs of cells at or above the threshold in each row are linked "
             "from the top down into zones, and a line through each zone gives its dip and "
             "dip direction (analysis/measure/faults.h, docs/analysis.md \"Faults\"). CSV, one row "
             "per zone ordered by x at its top: zone, x_top, y_top, x_bottom, y_bottom (m), "
             "dip (degrees), dips (left or right), rows, mean and max value. A summary line "
             "goes to standard error.",
    .options = options,
    .notes = "A thrust verges away from its dip direction: with the right wall pushing, "
             "forward-verging thrusts dip right.",
};

static int usage(const char *what) {
    cdem_cli_usage_print(stderr, &cdem_cmd_faults_help, what);
    return 2;
}

static int fail(const char *file, const cdem_error *err) {
    const char *m = err->msg[0] ? err->msg : "unknown error";
    if (!strncmp(m, "faults: ", 8))
        m += 8;
    if (file && !strstr(m, file))
        fprintf(stderr, "cdem-strain faults: %s: %s\n", file, m);
    else
        fprintf(stderr, "cdem-strain faults: %s\n", m);
    return 1;
}

static int parse_number(const char *text, double *out) {
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (errno || end == text || *end || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

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

int cdem_cmd_faults(int argc, char **argv) {
    const char *file = NULL, *out = NULL, *inc = "last", *qname = "total-max-shear";
    cdem_faults_options o;
    cdem_faults_default_options(&o);
    for (int i = 1; i < argc; i++) {
        if (cdem_cli_wants_help(argc, argv, i, &cdem_cmd_faults_help) == i) {
            cdem_cli_help_print(stdout, &cdem_cmd_faults_help);
            return 0;
        }
        const char *val = NULL;
        const cdem_cli_option *opt =
            argv[i][0] == '-' && argv[i][1]
                ? cdem_cli_find_option(&cdem_cmd_faults_help, argv[i], &val)
                : NULL;
        if (argv[i][0] == '-' && argv[i][1] && !opt) {
            char msg[160];
            snprintf(msg, sizeof msg, "unknown option '%.100s'", argv[i]);
            return usage(msg);
        }
        if (!opt) {
            if (file)
                return usage("need exactly one run file (RUN.h5)");
            file = argv[i];
            continue;
        }
        if (!val) {
            if (i + 1 >= argc) {
                char msg[160];
                snprintf(msg, sizeof msg, "%.100s needs a value", argv[i]);
                return usage(msg);
            }
            val = argv[++i];
        }
        double x;
        if (cdem_cli_option_is(opt, "--increment"))
            inc = val;
        else if (cdem_cli_option_is(opt, "--quantity"))
            qname = val;
        else if (cdem_cli_option_is(opt, "--output"))
            out = val;
        else if (cdem_cli_option_is(opt, "--threshold")) {
            if (!parse_number(val, &x) || !(x > 0.0))
                return usage("--threshold must be a number > 0");
            o.threshold = x;
        } else if (cdem_cli_option_is(opt, "--bin")) {
            if (!parse_number(val, &x) || !(x > 0.0))
                return usage("--bin must be a length in m > 0");
            o.bin = x;
        } else if (cdem_cli_option_is(opt, "--min-rows")) {
            if (!parse_number(val, &x) || x < 2 || x > 100000 || x != floor(x))
                return usage("--min-rows must be a whole number >= 2");
            o.min_rows = (int)x;
        }
    }
    if (!file)
        return usage("missing the run file (RUN.h5)");
    cdem_error err;
    const cdem_quantity *q;
    if (cdem_quantity_find(qname, &q, &err) != CDEM_OK)
        return fail(NULL, &err);
    cdem_analysis *a;
    if (cdem_analysis_open(file, &a, &err) != CDEM_OK)
        return fail(NULL, &err);
    size_t index = 0;
    const cdem_state *s = NULL;
    double *v = NULL;
    cdem_faults_result res = {0};
    cdem_status st = cdem_analysis_find(a, inc, &index, &err);
    if (st == CDEM_OK)
        st = cdem_analysis_values(a, index, q, &s, &v, &err);
    if (st == CDEM_OK)
        st = cdem_faults_pick(s, v, &o, &res, &err);
    if (st == CDEM_OK && !out)
        st = write_csv(stdout, &res, &err);
    else if (st == CDEM_OK) {
        /* written to OUT.tmp, renamed on success (outfile.h) */
        cdem_outfile of;
        st = cdem_outfile_begin(&of, out, &err);
        FILE *f = NULL;
        if (st == CDEM_OK && !(f = fopen(of.tmp, "w")))
            st = CDEM_FAIL(&err, CDEM_ERR_IO, "cannot create %s: %s", out, strerror(errno));
        if (st == CDEM_OK)
            st = write_csv(f, &res, &err);
        if (f && fclose(f) != 0 && st == CDEM_OK)
            st = CDEM_FAIL(&err, CDEM_ERR_IO, "error writing %s", out);
        st = cdem_outfile_end(&of, st, &err);
    }
    if (st == CDEM_OK) {
        size_t left = 0;
        for (size_t k = 0; k < res.n; k++)
            left += !res.zone[k].dips_right;
        fprintf(stderr,
                "cdem-strain faults: increment %d: %zu zones (%zu dip left, %zu dip right) of %s "
                ">= %g on cells of %.4g m\n",
                (int)cdem_analysis_info(a, index)->number, res.n, left, res.n - left, q->name,
                res.threshold, res.bin);
    }
    cdem_faults_free(&res);
    free(v);
    cdem_analysis_close(a);
    return st == CDEM_OK ? 0 : fail(file, &err);
}
