/* cmd_export_sspx: `cdem-strain export-sspx`; its help (below) says what it does. */
#include "cmd_options.h"

#include "analysis.h"
#include "outfile.h"
#include "params.h"
#include "sspx.h"

#include <stdio.h>

static int cmd_export_sspx(const cdem_cmd_options *o) {
    if (!o->increments)
        return cdem_cmd_usage(o->help,
                              "export-sspx needs --increments A-B (e.g. 56-282, equil-last)");
    if (!o->dir)
        return cdem_cmd_usage(o->help, "export-sspx needs an output directory");
    if (o->prefix && !cdem_params_prefix_ok(o->prefix)) { /* before any folder is made */
        char what[400];
        snprintf(what, sizeof what, "--prefix %.100s: %s", o->prefix, CDEM_PREFIX_RULE);
        return cdem_cmd_usage(o->help, what);
    }
    cdem_analysis *a;
    int rc = cdem_cmd_open_run(o, &a);
    if (rc)
        return rc;
    cdem_error err;
    size_t first, last, written;
    const char *prefix = o->prefix ? o->prefix : cdem_analysis_params(a)->prefix;
    if (!prefix[0])
        prefix = "cdem";
    cdem_status st = cdem_params_prefix_ok(prefix)
                         ? CDEM_OK
                         : CDEM_FAIL(&err, CDEM_ERR_FORMAT, "%s: stored output.prefix '%s' %s",
                                     o->file, prefix, CDEM_PREFIX_RULE);
    if (st == CDEM_OK)
        st = cdem_sspx_parse_range(a, o->increments, &first, &last, &err);
    if (st == CDEM_OK) /* after the run file and range are known good: no stray folder */
        st = cdem_outfile_make_dirs(o->dir, &err);
    if (st == CDEM_OK)
        st = cdem_sspx_export(a, first, last, o->dir, prefix, &written, &err);
    if (st == CDEM_OK)
        fprintf(stderr, "cdem-strain: wrote %zu files %s/%s%d.txt .. %s%d.txt\n", written, o->dir,
                prefix, (int)cdem_analysis_info(a, first)->number, prefix,
                (int)cdem_analysis_info(a, last)->number);
    cdem_analysis_close(a);
    return st == CDEM_OK ? CDEM_EXIT_OK : cdem_cmd_fail(NULL, NULL, &err);
}

static const char *const sspx_forms[] = {"RUN.h5 --increments A-B [--prefix P] DIR", NULL};
static const cdem_cli_option sspx_options[] = {
    {"--increments", "A-B",
     "increment range; numbers or first, last, equil on either side (e.g. 56-282, "
     "equil-last)"},
    {"--prefix", "P", "file-name prefix (default: output.prefix of the run, else cdem)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain export-sspx",
    .forms = sspx_forms,
    .about = "One SSPX text file per increment, DIR/<prefix><number>.txt, columns id x y radius "
             "layer (docs/formats-text.md); DIR is created when it does not exist.",
    .options = sspx_options,
};

CDEM_SIMPLE_COMMAND(export_sspx, "export-sspx", "one SSPX text file per increment", 2,
                    cmd_export_sspx);
