/* commands: the one table of cdem-strain's subcommands. A row is the name, the one-line
 * summary of the general help, the command's help (usage forms, description, options: the
 * usage text) and the handler. It drives everything about a command: dispatch (main.c),
 * `cdem-strain help`, `help COMMAND` and `COMMAND --help`, and through the help text the
 * man page (scripts/help2roff.py) and the bash completion (scripts/help2completion.py);
 * tests/test_help.c and tests/test_registry.c walk it.
 * A new subcommand is one new file, cli/cmd_NAME.c, defining its row
 * `const cdem_command cdem_command_NAME` (CDEM_SIMPLE_COMMAND, cmd_options.h, for one that
 * takes the common options), plus one line X(NAME) in CDEM_STRAIN_COMMANDS (commands.c);
 * docs/analysis.md lists it and a test runs it (tests/test_registry.c checks both).
 * Ownership: static const data. Thread safety: pure. */
#ifndef CDEM_COMMANDS_H
#define CDEM_COMMANDS_H

#include "cli_help.h"

#include <stddef.h>
#include <stdio.h>

typedef struct {
    const char *name;          /* the subcommand word */
    const char *summary;       /* one line in the general help */
    const cdem_cli_help *help; /* usage forms, description, options */
    /* argv[0] is the word; returns the exit status (0 ok, 1 error, 2 usage). -h/--help
     * never reaches it: the dispatcher prints help. */
    int (*run)(int argc, char **argv);
} cdem_command;

/* The rows, in the order of the general help; *n gets their number. */
const cdem_command *const *cdem_commands(size_t *n);

/* The row named name, or NULL. */
const cdem_command *cdem_command_find(const char *name);

/* The command name nearest to an unknown one, when close enough to offer (suggest.h), else
 * NULL. */
const char *cdem_command_suggest(const char *name);

/* The usage error of an unknown command into msg: "unknown command 'NAME'" + more, and the
 * nearest command when there is one to offer. */
void cdem_command_unknown(const char *name, const char *more, char *msg, size_t cap);

/* The general help of cdem-strain (usage forms, the command list, options). */
void cdem_commands_print_help(FILE *f);

/* Its usage forms and options, for usage errors of the program itself. */
extern const cdem_cli_help cdem_strain_help;

/* `cdem-strain RUN.h5 --increment K --quantity NAME ...`: compute with the run file first
 * (argv[0] is the file; cmd_compute.c). */
int cdem_cmd_compute_file_first(int argc, char **argv);

#endif
