/* cmd_faults: the faults subcommand of cdem-strain:
 *   faults RUN.h5 [--increment K|last|equil|first] [--quantity NAME] [--threshold V]
 *                 [--bin M] [--min-rows N] [--include-salt] [-o OUT.csv]
 *       fault zones picked from a strain field (measure/faults.h): one CSV row per zone
 *       with where it reaches up and down, its dip and dip direction; a summary on stderr.
 *   faults RUN.h5 --timeline [--band M] [--contrast C] [-o OUT.csv]
 *       which of the run's faults (its boundary actors) was active in which increments
 *       (measure/fault_timeline.h): one CSV row per deformation increment and fault; per
 *       fault a line on stderr with its measured and its prescribed window. */
#include "analysis.h"
#include "cmd_support.h"
#include "commands.h"
#include "fault_timeline.h"
#include "faults.h"
#include "quantity.h"
#include "run_file.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static const char synopsis[] = "RUN.h5 [--increment K|last|equil|first] [--quantity NAME] "
                               "[--threshold V] [--bin M] [--min-rows N] [--include-salt] "
                               "[-o OUT.csv]";
static const char timeline_synopsis[] = "RUN.h5 --timeline [--band M] [--contrast C] [-o OUT.csv]";
static const char *const forms[] = {synopsis, timeline_synopsis, NULL};
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
    {"--timeline", NULL,
     "which of the run's faults (its boundary actors) was active in which increments, from "
     "the incremental strain near each fault's trace"},
    {"--band", "M",
     "--timeline: half width of a fault's zone in m (default 2 x the largest free radius, at "
     "most a quarter of the smallest distance between two faults)"},
    {"--contrast", "C",
     "--timeline: a fault is active where its zone's mean strain is at least C times the "
     "increment's median in the lower half of the assembly (default 3)"},
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
             "forward-verging thrusts dip right. --timeline writes, per deformation increment "
             "and fault: increment, run_displacement (m of the run's boundary displacement), "
             "section, mode, x_base (m), displacement (m, the fault's own so far), score (the "
             "mean incr-max-shear of its zone over the increment's median), active (0/1), "
             "in_window (0/1); and per fault "
             "a line on standard error: measured active from increment A to B, prescribed "
             "window from C to D (docs/analysis.md \"Faults on a timeline\").",
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

static cdem_status write_timeline(FILE *f, const cdem_timeline_result *r, cdem_error *err) {
    fprintf(f, "increment,run_displacement,section,mode,x_base,displacement,score,active,"
               "in_window\n");
    for (size_t k = 0; k < r->n_inc; k++)
        for (int j = 0; j < r->n_actors; j++) {
            const cdem_timeline_actor *t = &r->actor[j];
            const size_t at = k * (size_t)r->n_actors + (size_t)j;
            const int in = r->first_window[j] >= 0 && r->number[k] >= r->first_window[j] &&
                           r->number[k] <= r->last_window[j];
            fprintf(f, "%d,%.6g,%s,%s,%.6g,%.6g,%.6g,%d,%d\n", r->number[k], r->run[k], t->section,
                    cdem_mode_name(t->mode), t->x_base,
                    cdem_timeline_actor_displacement(t, r->run[k]), r->score[at], r->active[at],
                    in);
        }
    if (ferror(f))
        return CDEM_FAIL(err, CDEM_ERR_IO, "error writing the CSV");
    return CDEM_OK;
}

/* faults --timeline: the CSV and one line per fault on stderr. */
static int run_timeline(const char *file, const char *out, const cdem_timeline_options *o) {
    cdem_error err;
    cdem_analysis *a;
    if (cdem_analysis_open(file, &a, &err) != CDEM_OK)
        return cdem_cmd_fail("faults", NULL, &err);
    cdem_timeline_result res;
    cdem_status st = cdem_timeline_measure(a, o, &res, &err);
    if (st == CDEM_OK) {
        cdem_cmd_output output;
        st = cdem_cmd_output_open(&output, out, &err);
        if (st == CDEM_OK)
            st = cdem_cmd_output_close(&output, write_timeline(output.f, &res, &err), &err);
    }
    if (st == CDEM_OK)
        for (int j = 0; j < res.n_actors; j++) {
            const cdem_timeline_actor *t = &res.actor[j];
            char measured[64], prescribed[64];
            if (res.first_active[j] < 0)
                snprintf(measured, sizeof measured, "never active");
            else
                snprintf(measured, sizeof measured, "active in increments %d-%d",
                         res.first_active[j], res.last_active[j]);
            if (res.first_window[j] < 0)
                snprintf(prescribed, sizeof prescribed, "no increment");
            else
                snprintf(prescribed, sizeof prescribed, "increments %d-%d", res.first_window[j],
                         res.last_window[j]);
            char stop[32];
            snprintf(stop, sizeof stop, t->stop > 0.0 ? "%g m" : "the end", t->stop);
            fprintf(stderr,
                    "cdem-strain faults: %s %s at x = %.6g m: %s; window %g m to %s (%s); zone "
                    "+-%.4g m\n",
                    t->section, cdem_mode_name(t->mode), t->x_base, measured, t->start, stop,
                    prescribed, res.band);
        }
    cdem_timeline_free(&res);
    cdem_analysis_close(a);
    return st == CDEM_OK ? 0 : cdem_cmd_fail("faults", file, &err);
}

static int run(int argc, char **argv) {
    const char *file = NULL, *out = NULL, *inc = "last", *qname = "total-max-shear";
    cdem_faults_options o;
    cdem_faults_default_options(&o);
    cdem_timeline_options to;
    cdem_timeline_default_options(&to);
    int timeline = 0;
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
        else if (cdem_cli_option_is(opt, "--timeline"))
            timeline = 1;
        else if (cdem_cli_option_is(opt, "--band")) {
            if (!cdem_cmd_parse_number(val, &x) || !(x > 0.0))
                return cdem_cmd_usage(&help, "--band must be a length in m > 0");
            to.band = x;
        } else if (cdem_cli_option_is(opt, "--contrast")) {
            if (!cdem_cmd_parse_number(val, &x) || !(x > 1.0))
                return cdem_cmd_usage(&help, "--contrast must be a number > 1");
            to.contrast = x;
        }
    }
    if (!file)
        return cdem_cmd_usage(&help, "missing the run file (RUN.h5)");
    if (timeline)
        return run_timeline(file, out, &to);
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
