/* cmd_limits: `cdem-strain limits`; its help (below) says what it does. */
#include "cmd_options.h"

#include "analysis.h"
#include "quantity.h"

#include <stdio.h>

static int cmd_limits(const cdem_cmd_options *o) {
    if (!o->increment || !o->quantity)
        return cdem_cmd_usage(o->help, "limits needs --increment K and --quantity NAME");
    cdem_error err;
    const cdem_quantity *q;
    cdem_analysis *a;
    int rc = cdem_cmd_open_run_quantity(o, &q, &a);
    if (rc)
        return rc;
    size_t k;
    cdem_limits l;
    if (cdem_analysis_find(a, o->increment, &k, &err) != CDEM_OK ||
        cdem_analysis_limits(a, k, q, &l, &err) != CDEM_OK) {
        cdem_analysis_close(a);
        return cdem_cmd_fail(NULL, NULL, &err);
    }
    printf("quantity %s (%s)\n", q->name, q->label);
    printf("scale %s\n", q->scale == CDEM_SCALE_SIGNED ? "signed (blue-white-red)"
                                                       : "magnitude (blue-green-red)");
    printf("vmin %.9g %s\nvmax %.9g %s\nthreshold %.9g %s\n", l.vmin, q->unit, l.vmax, q->unit,
           l.threshold, q->unit);
    cdem_analysis_close(a);
    return CDEM_EXIT_OK;
}

static const char *const limits_forms[] = {"RUN.h5 --increment K --quantity NAME", NULL};
static const cdem_cli_option limits_options[] = {
    {"--increment", "K|last|equil|first", "the increment"},
    {"--quantity", "NAME", "the quantity ('cdem-strain quantities' lists the names)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain limits",
    .forms = limits_forms,
    .about = "The colour-bar limits render uses for a quantity at an increment: minimum, "
             "maximum, the 0.1 x maximum threshold and the colour scale (docs/analysis.md, "
             "\"Colour limits\").",
    .options = limits_options,
};

CDEM_SIMPLE_COMMAND(limits, "limits", "colour-bar limits of a quantity at an increment", 1,
                    cmd_limits);
