/* commands: the table of cdem-strain's subcommands (name, entry point, help, one-line
 * summary) and the program's general help. main.c dispatches through it; `help COMMAND`,
 * `COMMAND --help`, the man page (scripts/help2roff.py) and the bash completion
 * (scripts/completion.py) walk it, and tests/test_help.c checks every row. A new subcommand
 * is one row here plus its cdem_cli_help next to its parser.
 * Ownership: static const data. Thread safety: pure. */
#ifndef CDEM_COMMANDS_H
#define CDEM_COMMANDS_H

#include "cli_help.h"

#include <stddef.h>
#include <stdio.h>

typedef struct {
    const char *name;                  /* the subcommand word */
    int (*run)(int argc, char **argv); /* argv[0] is the word; returns the exit status */
    const cdem_cli_help *help;         /* usage, description, options */
    const char *summary;               /* one line in the general help */
} cdem_command;

/* The rows, in the order of the general help; *n gets their number. */
const cdem_command *cdem_commands(size_t *n);

/* The row named name, or NULL. */
const cdem_command *cdem_command_find(const char *name);

/* The general help of cdem-strain (usage forms, the command list, options). */
void cdem_commands_print_help(FILE *f);

/* Its usage forms and options, for usage errors of the program itself. */
extern const cdem_cli_help cdem_strain_help;

#endif
