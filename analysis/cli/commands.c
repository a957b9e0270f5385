/* commands: see commands.h. The general help's command list is built from the table at
 * print time, so a row added to the table is listed without another edit. */
#include "commands.h"

#include "cmd_support.h"
#include "suggest.h"

#include <string.h>

/* The subcommands in the order of the general help: cmd_NAME.c defines cdem_command_NAME. */
#define CDEM_STRAIN_COMMANDS(X)                                                                    \
    X(info)                                                                                        \
    X(compute)                                                                                     \
    X(element)                                                                                     \
    X(limits)                                                                                      \
    X(render)                                                                                      \
    X(series)                                                                                      \
    X(plot_series)                                                                                 \
    X(mohr)                                                                                        \
    X(repose)                                                                                      \
    X(calibrate)                                                                                   \
    X(voids)                                                                                       \
    X(faults)                                                                                      \
    X(fault_seal)                                                                                  \
    X(wedge)                                                                                       \
    X(plot_csv)                                                                                    \
    X(export_sspx)                                                                                 \
    X(export_biaxial)                                                                              \
    X(import_cdem2d)                                                                               \
    X(xdmf)                                                                                        \
    X(quantities)                                                                                  \
    X(help)

#define DECLARE_ROW(id) extern const cdem_command cdem_command_##id;
CDEM_STRAIN_COMMANDS(DECLARE_ROW)
#define ROW(id) &cdem_command_##id,
static const cdem_command *const table[] = {CDEM_STRAIN_COMMANDS(ROW)};
#define N_COMMANDS (sizeof table / sizeof table[0])

static int cmd_help(int argc, char **argv);

static const char *const help_forms[] = {"[COMMAND]", NULL};
static const cdem_cli_option help_options[] = {{NULL, NULL, NULL}};
static const cdem_cli_help help_help = {
    .program = "cdem-strain help",
    .forms = help_forms,
    .about = "Without COMMAND the general help of cdem-strain; with COMMAND the usage, "
             "description and options of that command (the same as 'cdem-strain COMMAND "
             "--help').",
    .options = help_options,
};

const cdem_command cdem_command_help = {"help", "the general help, or the help of one command",
                                        &help_help, cmd_help};

const cdem_command *const *cdem_commands(size_t *n) {
    *n = N_COMMANDS;
    return table;
}

const cdem_command *cdem_command_find(const char *name) {
    for (size_t k = 0; k < N_COMMANDS; k++)
        if (!strcmp(table[k]->name, name))
            return table[k];
    return NULL;
}

const char *cdem_command_suggest(const char *name) {
    const char *names[N_COMMANDS];
    for (size_t k = 0; k < N_COMMANDS; k++)
        names[k] = table[k]->name;
    return cdem_suggest(name, names, N_COMMANDS);
}

void cdem_command_unknown(const char *name, const char *more, char *msg, size_t cap) {
    const char *near = cdem_command_suggest(name);
    snprintf(msg, cap, "unknown command '%.100s'%s%s%s%s", name, more,
             near ? "; did you mean '" : "", near ? near : "", near ? "'?" : "");
}

static const char *const strain_forms[] = {"COMMAND [ARGS]...",
                                           "RUN.h5 --increment K --quantity NAME [...]",
                                           "help [COMMAND]", "-V|--version | -h|--help", NULL};
static const cdem_cli_option strain_options[] = {
    {"-V, --version", NULL, "print the version and exit"}, {NULL, NULL, NULL}};

const cdem_cli_help cdem_strain_help = {
    .program = "cdem-strain",
    .forms = strain_forms,
    .about = "Analyses cdem-run results (and imported cdem2D simulations): displacement, "
             "incremental, total and cumulative strain, stress, principal axes and colour "
             "limits; pictures, plots and text exports. A run file as the first argument "
             "means compute. 'cdem-strain help COMMAND' or "
             "'cdem-strain COMMAND --help' shows a command's usage and options.",
    .rows_heading = "Commands",
    .options = strain_options,
    .notes = "Quantities, formulas and rules: docs/analysis.md; pictures: docs/rendering.md; "
             "text formats: docs/formats-text.md; the user guide: docs/guide.md.",
};

void cdem_commands_print_help(FILE *f) {
    cdem_cli_row rows[N_COMMANDS + 1];
    for (size_t k = 0; k < N_COMMANDS; k++)
        rows[k] = (cdem_cli_row){table[k]->name, table[k]->summary};
    rows[N_COMMANDS] = (cdem_cli_row){NULL, NULL};
    cdem_cli_help h = cdem_strain_help;
    h.rows = rows;
    cdem_cli_help_print(f, &h);
}

static int cmd_help(int argc, char **argv) {
    if (argc < 2) {
        cdem_commands_print_help(stdout);
        return 0;
    }
    const cdem_command *c = cdem_command_find(argv[1]);
    if (!c || argc > 2) {
        char msg[200];
        if (c)
            snprintf(msg, sizeof msg, "one command at a time");
        else
            cdem_command_unknown(argv[1], "", msg, sizeof msg);
        return cdem_cmd_usage(&help_help, msg);
    }
    cdem_cli_help_print(stdout, c->help);
    return 0;
}
