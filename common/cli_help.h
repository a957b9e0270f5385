/* cli_help: one description per program and subcommand (usage forms, prose, option table)
 * printed by -h/--help in one layout, so every command reads the same way and the man pages
 * (scripts/help2roff.py), the bash completion (scripts/help2completion.py) and the parsers of
 * cdem-strain's simple commands come from the same table. Printed layout, 80 columns:
 *   usage: PROGRAM FORM             later forms under it; long forms wrap, never inside [...]
 *   <blank> description paragraphs  (a paragraph starting with a space is printed as is)
 *   <blank> Heading:                "Commands:" (rows) and "Options:"; rows indented by two,
 *     -o, --output FILE  text       text from column 23, or on the next line
 *   <blank> notes paragraphs
 *   <blank> Exit status: ...
 * help2roff.py and tests/test_help.c rely on this layout.
 * Ownership: descriptions are static const data. Thread safety: pure functions. */
#ifndef CDEM_CLI_HELP_H
#define CDEM_CLI_HELP_H

#include <stddef.h>
#include <stdio.h>

/* One option. names: the spellings, comma-separated ("-o, --output"); arg: the value's
 * metavariable ("OUT.csv") or NULL for a switch; help: what it does (wrapped). */
typedef struct {
    const char *names;
    const char *arg;
    const char *help;
} cdem_cli_option;

/* One row of a list under a heading other than "Options:" (the commands of cdem-strain). */
typedef struct {
    const char *name;
    const char *help;
} cdem_cli_row;

typedef struct {
    const char *program;            /* "cdem-run", "cdem-strain render" */
    const char *const *forms;       /* usage forms after the program, NULL-terminated */
    const char *about;              /* description; "\n\n" separates paragraphs */
    const char *rows_heading;       /* e.g. "Commands" (without ':'), or NULL */
    const cdem_cli_row *rows;       /* rows under rows_heading, {NULL}-terminated */
    const cdem_cli_option *options; /* {NULL}-terminated; -h/--help is added */
    const char *notes;              /* paragraphs after the options, or NULL */
    const char *exit_status;        /* "0 success, 1 error, 2 usage error." */
} cdem_cli_help;

/* Width of printed help; the option text column. */
#define CDEM_CLI_HELP_WIDTH  80
#define CDEM_CLI_HELP_COLUMN 23

/* Prints h in the layout above. */
void cdem_cli_help_print(FILE *f, const cdem_cli_help *h);

/* A usage error: "PROGRAM: what", the first usage form and "Try 'PROGRAM --help' ...". The
 * caller returns exit status 2. */
void cdem_cli_usage_print(FILE *f, const cdem_cli_help *h, const char *what);

/* Index of argv[first..argc-1] that is -h or --help, else 0. An argument that is the value
 * of an option taking one (per h's table) is skipped, so `--prefix -h` is not help. */
int cdem_cli_wants_help(int argc, char *const *argv, int first, const cdem_cli_help *h);

/* The option of h spelled `arg` (exactly one of its names, or "name=value" when it takes a
 * value); NULL when h has none. *inline_value gets the text after '=' or NULL. */
const cdem_cli_option *cdem_cli_find_option(const cdem_cli_help *h, const char *arg,
                                            const char **inline_value);

/* The long spelling of h's options (or --help) nearest to the unknown option arg ("--name"
 * or "--name=value"), written into buf, when it is close enough to offer (suggest.h); NULL
 * otherwise and for a one-letter option. */
const char *cdem_cli_suggest_option(const cdem_cli_help *h, const char *arg, char *buf, size_t cap);

/* 1 when option o has the spelling name (one of its comma-separated names). */
int cdem_cli_option_is(const cdem_cli_option *o, const char *name);

#endif
