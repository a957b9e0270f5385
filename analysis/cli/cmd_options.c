/* cmd_options: see cmd_options.h. */
#include "cmd_options.h"

#include "run_file.h"

#include <stddef.h>
#include <string.h>

/* Where each option's value goes, by its long name: a value (const char *) or, for a
 * switch, a flag (int) set to 1. */
static const struct {
    const char *name;
    size_t offset;
} fields[] = {{"--increment", offsetof(cdem_cmd_options, increment)},
              {"--increments", offsetof(cdem_cmd_options, increments)},
              {"--quantity", offsetof(cdem_cmd_options, quantity)},
              {"--format", offsetof(cdem_cmd_options, format)},
              {"--output", offsetof(cdem_cmd_options, out)},
              {"--prefix", offsetof(cdem_cmd_options, prefix)},
              {"--element", offsetof(cdem_cmd_options, element)},
              {"--xdmf2", offsetof(cdem_cmd_options, xdmf2)},
              {"--json", offsetof(cdem_cmd_options, json)}};

/* Fills o from argv[first..]: only the options of h's table; positional arguments are the
 * file, then (positionals 2) the directory. Returns 0 or 2 (message printed). */
static int parse_options(int argc, char **argv, int first, const cdem_cli_help *h, int positionals,
                         cdem_cmd_options *o) {
    memset(o, 0, sizeof *o);
    o->help = h;
    for (int i = first; i < argc; i++) {
        const cdem_cli_option *opt;
        const char *val;
        const cdem_cmd_arg kind = cdem_cmd_next_arg(h, argc, argv, &i, &opt, &val);
        if (kind == CDEM_CMD_ARG_USAGE)
            return CDEM_EXIT_USAGE;
        if (kind == CDEM_CMD_ARG_OPTION) {
            size_t f = 0;
            while (f < sizeof fields / sizeof fields[0] && !cdem_cli_option_is(opt, fields[f].name))
                f++;
            if (f == sizeof fields / sizeof fields[0])
                return cdem_cmd_usage(h, "internal: an option of the help table has no field");
            if (opt->arg)
                *(const char **)((char *)o + fields[f].offset) = val;
            else
                *(int *)((char *)o + fields[f].offset) = 1;
        } else if (!o->file) {
            o->file = argv[i];
        } else if (!o->dir && positionals > 1) {
            o->dir = argv[i];
        } else {
            char msg[160];
            snprintf(msg, sizeof msg, "unexpected argument '%.100s'", argv[i]);
            return cdem_cmd_usage(h, msg);
        }
    }
    return CDEM_EXIT_OK;
}

int cdem_cmd_options_run(int argc, char **argv, int first, const cdem_cli_help *h, int positionals,
                         int (*fn)(const cdem_cmd_options *)) {
    cdem_cmd_options o;
    const int rc = parse_options(argc, argv, first, h, positionals, &o);
    return rc ? rc : fn(&o);
}

int cdem_cmd_open_run(const cdem_cmd_options *o, cdem_analysis **a) {
    cdem_error err;
    if (!o->file)
        return cdem_cmd_usage(o->help, "missing the run file (RUN.h5)");
    if (cdem_analysis_open(o->file, a, &err) != CDEM_OK)
        return cdem_cmd_fail(NULL, NULL, &err);
    return CDEM_EXIT_OK;
}

int cdem_cmd_open_run_quantity(const cdem_cmd_options *o, const cdem_quantity **q,
                               cdem_analysis **a) {
    cdem_error err;
    if (cdem_quantity_find(o->quantity, q, &err) != CDEM_OK)
        return cdem_cmd_fail(NULL, NULL, &err);
    return cdem_cmd_open_run(o, a);
}
