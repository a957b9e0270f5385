/* cmd_options: see cmd_options.h. */
#include "cmd_options.h"

#include "run_file.h"

#include <stddef.h>
#include <string.h>

/* Where each option's value goes, by its long name. */
static const struct {
    const char *name;
    size_t offset;
} option_fields[] = {{"--increment", offsetof(cdem_cmd_options, increment)},
                     {"--increments", offsetof(cdem_cmd_options, increments)},
                     {"--quantity", offsetof(cdem_cmd_options, quantity)},
                     {"--format", offsetof(cdem_cmd_options, format)},
                     {"--output", offsetof(cdem_cmd_options, out)},
                     {"--prefix", offsetof(cdem_cmd_options, prefix)},
                     {"--element", offsetof(cdem_cmd_options, element)}};

static const struct {
    const char *name;
    size_t offset;
} switch_fields[] = {{"--xdmf2", offsetof(cdem_cmd_options, xdmf2)},
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
        if (kind == CDEM_CMD_ARG_OPTION && !opt->arg) { /* a switch */
            size_t f = 0;
            while (f < sizeof switch_fields / sizeof switch_fields[0] &&
                   !cdem_cli_option_is(opt, switch_fields[f].name))
                f++;
            if (f == sizeof switch_fields / sizeof switch_fields[0])
                return cdem_cmd_usage(h, "internal: a switch of the help table has no field");
            *(int *)((char *)o + switch_fields[f].offset) = 1;
        } else if (kind == CDEM_CMD_ARG_OPTION) {
            size_t f = 0;
            while (f < sizeof option_fields / sizeof option_fields[0] &&
                   !cdem_cli_option_is(opt, option_fields[f].name))
                f++;
            if (f == sizeof option_fields / sizeof option_fields[0])
                return cdem_cmd_usage(h, "internal: an option of the help table has no field");
            *(const char **)((char *)o + option_fields[f].offset) = val;
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
