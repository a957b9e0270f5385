/* cmd_compute: `cdem-strain compute`; its help (below) says what it does. */
#include "cmd_options.h"

#include "analysis.h"
#include "outfile.h"
#include "qexport.h"
#include "quantity.h"
#include "xdmf.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmd_compute(const cdem_cmd_options *o) {
    if (!o->increment)
        return cdem_cmd_usage(o->help, "compute needs --increment K|last|equil|first|all");
    if (!o->quantity)
        return cdem_cmd_usage(o->help,
                              "compute needs --quantity NAME (see 'cdem-strain quantities')");
    const char *format = o->format ? o->format : "csv";
    if (strcmp(format, "csv") != 0 && strcmp(format, "h5") != 0)
        return cdem_cmd_usage(o->help, "--format must be csv or h5");
    if (strcmp(format, "h5") == 0 && !o->out)
        return cdem_cmd_usage(o->help, "--format h5 needs -o OUT.h5");
    cdem_error err;
    const cdem_quantity *q;
    cdem_analysis *a;
    int rc = cdem_cmd_open_run_quantity(o, &q, &a);
    if (rc)
        return rc;
    size_t first, last;
    int all = strcmp(o->increment, "all") == 0;
    if (all) {
        first = 0;
        last = cdem_analysis_count(a) - 1;
    } else if (cdem_analysis_find(a, o->increment, &first, &err) != CDEM_OK) {
        cdem_analysis_close(a);
        return cdem_cmd_fail(NULL, NULL, &err);
    } else {
        last = first;
    }
    FILE *f = stdout;
    cdem_qexport_h5 *h = NULL;
    cdem_status st = CDEM_OK;
    cdem_outfile of = {.active = 0}; /* -o OUT is written to OUT.tmp, renamed on success */
    if (o->out)
        st = cdem_outfile_begin(&of, o->out, &err);
    if (st == CDEM_OK && strcmp(format, "h5") == 0) {
        st = cdem_qexport_h5_create(of.tmp, q, &h, &err);
    } else if (st == CDEM_OK && o->out) {
        f = fopen(of.tmp, "w");
        if (!f)
            st = CDEM_FAIL(&err, CDEM_ERR_IO, "cannot create %s: %s", of.tmp, strerror(errno));
    }
    /* "all" skips increments without stress; with none at all that is an error, found before
     * anything is written (on stdout a header followed by an error is a broken CSV) */
    size_t with_stress = 0;
    for (size_t k = first; k <= last; k++)
        with_stress += cdem_analysis_info(a, k)->has_stress != 0;
    if (st == CDEM_OK && q->needs_stress && all && with_stress == 0)
        st = CDEM_FAIL(&err, CDEM_ERR_NOTFOUND,
                       "quantity '%s' needs stress, but no increment of %s stores any (run with "
                       "physics.calculate_stress = on)",
                       q->name, o->file);
    int header_done = h != NULL; /* the CSV header goes out with the first computed rows */
    for (size_t k = first; k <= last && st == CDEM_OK; k++) {
        const cdem_increment_info *in = cdem_analysis_info(a, k);
        if (q->needs_stress && !in->has_stress && all)
            continue;
        const cdem_state *s;
        double *v;
        st = cdem_analysis_values(a, k, q, &s, &v, &err);
        if (st != CDEM_OK)
            break;
        if (!header_done) {
            st = cdem_qexport_csv_header(f, all, &err);
            header_done = 1;
        }
        if (st == CDEM_OK)
            st = h ? cdem_qexport_h5_write(h, in->number, in->time, s, v, &err)
                   : cdem_qexport_csv_rows(f, all, in->number, s, v, &err);
        free(v);
    }
    if (h) {
        cdem_error e2;
        cdem_status st2 = cdem_qexport_h5_close(h, &e2);
        if (st == CDEM_OK && st2 != CDEM_OK) {
            err = e2;
            st = st2;
        }
    }
    if (f && f != stdout && fclose(f) != 0 && st == CDEM_OK)
        st = CDEM_FAIL(&err, CDEM_ERR_IO, "error writing %s", of.tmp);
    if (of.active)
        st = cdem_outfile_end(&of, st, &err);
    if (st == CDEM_OK && strcmp(format, "h5") == 0) /* its sidecar, once the file has its name */
        st = cdem_qexport_write_xdmf(o->out, NULL, CDEM_XDMF3, NULL, &err);
    cdem_analysis_close(a);
    return st == CDEM_OK ? CDEM_EXIT_OK : cdem_cmd_fail(NULL, NULL, &err);
}

static const char *const compute_forms[] = {
    "RUN.h5 --increment K|last|equil|first|all --quantity NAME [--format csv|h5] [-o OUT]", NULL};
static const cdem_cli_option compute_options[] = {
    {"--increment", "K|last|equil|first|all",
     "the increment (a number, first, last, equil = the end of equilibration), or all"},
    {"--quantity", "NAME", "what to compute ('cdem-strain quantities' lists the names)"},
    {"--format", "csv|h5",
     "CSV id,x,y,value (increment,id,x,y,value with --increment all; default) or HDF5 "
     "(needs -o; a .xmf sidecar is written next to it)"},
    {"-o, --output", "OUT", "output file (default: CSV on standard output)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain compute",
    .forms = compute_forms,
    .about = "Per-element values of one quantity (displacement, strain, stress, ...) at one "
             "increment or every increment. 'cdem-strain RUN.h5 --increment K --quantity NAME' "
             "is the same command. Formulas: docs/analysis.md.",
    .options = compute_options,
};

CDEM_SIMPLE_COMMAND(compute, "compute",
                    "per-element values of a quantity (CSV id,x,y,value, or HDF5)", 1, cmd_compute);

int cdem_cmd_compute_file_first(int argc, char **argv) {
    return cdem_cmd_options_run(argc, argv, 0, &help, 1, cmd_compute);
}
