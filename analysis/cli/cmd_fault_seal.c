/* cmd_fault_seal: the fault-seal subcommand of cdem-strain:
 *   fault-seal RUN.h5 [--increment K|last|equil|first] [--fault-x X] [--half-width W]
 *              [--band B] [--step S] [--seal-layers L1,L2,...]
 *              [--table juxtaposition|throw|seals] [-o OUT.csv]
 *       throw, heave and layer juxtaposition across one fault zone (measure/fault_seal.h):
 *       the zone is one of `faults`' zones (the strongest, or the nearest to --fault-x); one
 *       CSV table, a summary on stderr. */
#include "analysis.h"
#include "cmd_support.h"
#include "commands.h"
#include "fault_seal.h"
#include "faults.h"
#include "quantity.h"
#include "run_file.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SEALS 64

static const char synopsis[] =
    "RUN.h5 [--increment K|last|equil|first] [--fault-x X] [--half-width W] [--band B] "
    "[--step S] [--seal-layers L1,L2,...] [--table juxtaposition|throw|seals] [-o OUT.csv]";
static const char *const forms[] = {synopsis, NULL};
static const cdem_cli_option options[] = {
    {"--increment", "K|last|equil|first", "the increment (default last)"},
    {"--fault-x", "X",
     "the fault zone nearest x = X m at mid-height (default: the strongest zone, the largest "
     "mean total-max-shear x rows)"},
    {"--half-width", "W", "m, half the zone's width (default: the zone picking's cell size)"},
    {"--band", "B",
     "m, width of the band just outside the zone where horizons are read (default 4 x the "
     "cell size)"},
    {"--step", "S", "m, height step of the juxtaposition table (default half the mean radius)"},
    {"--seal-layers", "L1,L2,...", "layers that seal: the throw at which each stops facing itself"},
    {"--table", "juxtaposition|throw|seals",
     "the CSV written (default juxtaposition: height, footwall layer, hanging-wall layer)"},
    {"-o, --output", "OUT.csv", "output file (default: standard output)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain fault-seal",
    .forms = forms,
    .about = "Throw, heave and layer juxtaposition across one fault zone at one increment "
             "(analysis/measure/fault_seal.h, docs/analysis.md \"Fault seal\"). The zone is picked "
             "as by 'cdem-strain faults' from total-max-shear; the top of each layer (its horizon) "
             "is read just outside the zone on either side, the lower side is the hanging wall, "
             "and throw = footwall top - hanging-wall top. Tables (--table): juxtaposition "
             "(height, footwall_layer, hanging_wall_layer; 0 where a side has no layer), throw "
             "(layer, height, footwall_top, hanging_wall_top, throw, heave) and seals (layer, "
             "footwall and hanging-wall base and top, throw, overlap, self_juxtaposed, "
             "loss_throw: the throw at which the layer stops facing itself). A summary with the "
             "total throw goes to standard error.",
    .options = options,
    .notes = "2-D and one zone at a time; throw partitioning, smear and zones through time are "
             "not measured yet (issue 49).",
};

typedef enum { TABLE_JUXTAPOSITION, TABLE_THROW, TABLE_SEALS } table_kind;

static cdem_status write_csv(FILE *f, table_kind t, const cdem_fault_seal_result *r,
                             cdem_error *err) {
    if (t == TABLE_JUXTAPOSITION) {
        fprintf(f, "height,footwall_layer,hanging_wall_layer\n");
        for (size_t k = 0; k < r->n_rows; k++)
            fprintf(f, "%.6g,%d,%d\n", r->row[k].height, r->row[k].footwall, r->row[k].hanging);
    } else if (t == TABLE_THROW) {
        fprintf(f, "layer,height,footwall_top,hanging_wall_top,throw,heave\n");
        for (size_t k = 0; k < r->n_horizons; k++) {
            const cdem_seal_horizon *h = &r->horizon[k];
            fprintf(f, "%d,%.6g,%.6g,%.6g,%.6g,%.6g\n", h->layer, h->height, h->footwall_top,
                    h->hanging_top, h->throw_m, h->heave);
        }
    } else {
        fprintf(f, "layer,footwall_base,footwall_top,hanging_wall_base,hanging_wall_top,throw,"
                   "overlap,self_juxtaposed,loss_throw\n");
        for (size_t k = 0; k < r->n_seals; k++) {
            const cdem_seal_layer *q = &r->seal[k];
            fprintf(f, "%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%s,%.6g\n", q->layer, q->footwall_base,
                    q->footwall_top, q->hanging_base, q->hanging_top, q->throw_m, q->overlap,
                    q->self_juxtaposed ? "yes" : "no", q->loss_throw);
        }
    }
    if (ferror(f))
        return CDEM_FAIL(err, CDEM_ERR_IO, "error writing the CSV");
    return CDEM_OK;
}

/* Parses "L1,L2,..." into layers (>= 1); returns the count, or -1 on a bad list. */
static int parse_layers(const char *text, int *layers) {
    int n = 0;
    const char *p = text;
    while (*p) {
        char *end;
        const long v = strtol(p, &end, 10);
        if (end == p || v < 1 || v > 100000 || n == MAX_SEALS || (*end && *end != ','))
            return -1;
        layers[n++] = (int)v;
        p = *end ? end + 1 : end;
        if (*end && !*p)
            return -1;
    }
    return n > 0 ? n : -1;
}

/* The zone: the strongest of the picked zones (mean value x rows), or the one nearest x at
 * mid-height when want_x is finite. */
static cdem_status choose_zone(const cdem_faults_result *fr, double want_x, cdem_fault_zone *out,
                               cdem_error *err) {
    if (fr->n == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "no fault zone is found at this increment (see 'cdem-strain faults')");
    size_t best = 0;
    double best_score = -INFINITY;
    for (size_t k = 0; k < fr->n; k++) {
        const cdem_fault_zone *z = &fr->zone[k];
        const double score = isfinite(want_x) ? -fabs(0.5 * (z->x_top + z->x_bottom) - want_x)
                                              : z->mean_value * (double)z->rows;
        if (score > best_score) {
            best_score = score;
            best = k;
        }
    }
    *out = fr->zone[best];
    return CDEM_OK;
}

static int run(int argc, char **argv) {
    const char *file = NULL, *out = NULL, *inc = "last";
    double want_x = NAN, half_width = NAN, band = NAN, step = 0.0;
    int seals[MAX_SEALS], n_seals = 0;
    table_kind table = TABLE_JUXTAPOSITION;
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
        else if (cdem_cli_option_is(opt, "--output"))
            out = val;
        else if (cdem_cli_option_is(opt, "--fault-x")) {
            if (!cdem_cmd_parse_number(val, &x))
                return cdem_cmd_usage(&help, "--fault-x must be a position in m");
            want_x = x;
        } else if (cdem_cli_option_is(opt, "--half-width")) {
            if (!cdem_cmd_parse_number(val, &x) || !(x >= 0.0))
                return cdem_cmd_usage(&help, "--half-width must be a length in m >= 0");
            half_width = x;
        } else if (cdem_cli_option_is(opt, "--band")) {
            if (!cdem_cmd_parse_number(val, &x) || !(x > 0.0))
                return cdem_cmd_usage(&help, "--band must be a length in m > 0");
            band = x;
        } else if (cdem_cli_option_is(opt, "--step")) {
            if (!cdem_cmd_parse_number(val, &x) || !(x > 0.0))
                return cdem_cmd_usage(&help, "--step must be a length in m > 0");
            step = x;
        } else if (cdem_cli_option_is(opt, "--seal-layers")) {
            n_seals = parse_layers(val, seals);
            if (n_seals < 0)
                return cdem_cmd_usage(&help, "--seal-layers must be a comma-separated list of "
                                             "layer numbers >= 1 (at most 64)");
        } else if (cdem_cli_option_is(opt, "--table")) {
            if (!strcmp(val, "juxtaposition"))
                table = TABLE_JUXTAPOSITION;
            else if (!strcmp(val, "throw"))
                table = TABLE_THROW;
            else if (!strcmp(val, "seals"))
                table = TABLE_SEALS;
            else
                return cdem_cmd_usage(&help, "--table must be juxtaposition, throw or seals");
        }
    }
    if (!file)
        return cdem_cmd_usage(&help, "missing the run file (RUN.h5)");
    cdem_error err;
    const cdem_quantity *q;
    if (cdem_quantity_find("total-max-shear", &q, &err) != CDEM_OK)
        return cdem_cmd_fail("fault-seal", NULL, &err);
    cdem_analysis *a;
    if (cdem_analysis_open(file, &a, &err) != CDEM_OK)
        return cdem_cmd_fail("fault-seal", NULL, &err);
    size_t index = 0;
    const cdem_state *s = NULL;
    double *v = NULL;
    cdem_faults_result fr = {0};
    cdem_fault_seal_result res = {0};
    cdem_fault_zone zone = {0};
    cdem_faults_options fo;
    cdem_faults_default_options(&fo);
    cdem_status st = cdem_analysis_find(a, inc, &index, &err);
    if (st == CDEM_OK)
        st = cdem_analysis_values(a, index, q, &s, &v, &err);
    if (st == CDEM_OK)
        st = cdem_faults_pick(s, v, &fo, &fr, &err);
    if (st == CDEM_OK)
        st = choose_zone(&fr, want_x, &zone, &err);
    if (st == CDEM_OK) {
        const cdem_seal_zone z = {zone.x_top,
                                  zone.y_top,
                                  zone.x_bottom,
                                  zone.y_bottom,
                                  isfinite(half_width) ? half_width : fr.bin,
                                  isfinite(band) ? band : 4.0 * fr.bin};
        st = cdem_fault_seal_measure(s, &z, seals, (size_t)n_seals, step, &res, &err);
    }
    if (st == CDEM_OK) {
        cdem_cmd_output output;
        st = cdem_cmd_output_open(&output, out, &err);
        if (st == CDEM_OK)
            st = cdem_cmd_output_close(&output, write_csv(output.f, table, &res, &err), &err);
    }
    if (st == CDEM_OK) {
        fprintf(stderr,
                "cdem-strain fault-seal: increment %d: zone from (%.6g, %.6g) to (%.6g, %.6g) m, "
                "hanging wall on the %s; total throw %.4g m, heave %.4g m over %zu horizons\n",
                (int)cdem_analysis_info(a, index)->number, zone.x_top, zone.y_top, zone.x_bottom,
                zone.y_bottom, res.hanging_wall_right ? "right" : "left", res.total_throw,
                res.total_heave, res.n_horizons);
        for (size_t k = 0; k < res.n_seals; k++)
            fprintf(stderr,
                    "cdem-strain fault-seal: seal layer %d: throw %.4g m, overlap %.4g m, %s; "
                    "self-juxtaposition lost at a throw of %.4g m\n",
                    res.seal[k].layer, res.seal[k].throw_m, res.seal[k].overlap,
                    res.seal[k].self_juxtaposed ? "self-juxtaposed" : "not self-juxtaposed",
                    res.seal[k].loss_throw);
    }
    cdem_fault_seal_free(&res);
    cdem_faults_free(&fr);
    free(v);
    cdem_analysis_close(a);
    return st == CDEM_OK ? 0 : cdem_cmd_fail("fault-seal", file, &err);
}

const cdem_command cdem_command_fault_seal = {
    "fault-seal", "throw, heave and layer juxtaposition across one fault zone", &help, run};
