/* cmd_support: what every cdem-strain subcommand shares, so that a command's file holds
 * only its own work and all commands read and fail the same way:
 *   - the option loop: every command accepts exactly the options of its help table
 *     (cli_help.h), spelled any of their ways, "--opt VALUE" or "--opt=VALUE"; an unknown
 *     option or a missing value is a usage error in one wording;
 *   - usage errors (the command's first usage form and a pointer to its --help, exit 2) and
 *     failures ("cdem-strain CMD: [RUN.h5: ]message" on stderr, exit 1);
 *   - the number parsers of option values;
 *   - text output that goes to standard output or, with -o OUT, to OUT.tmp renamed to OUT
 *     on success (outfile.h).
 * -h/--help never reaches a command: the dispatcher (main.c, commands.h) prints the help.
 * Ownership: nothing is kept. Thread safety: one command at a time per process. */
#ifndef CDEM_CMD_SUPPORT_H
#define CDEM_CMD_SUPPORT_H

#include "cdem_error.h"
#include "cli_help.h"
#include "outfile.h"

#include <stdio.h>

enum { CDEM_EXIT_OK = 0, CDEM_EXIT_ERROR = 1, CDEM_EXIT_USAGE = 2 };

/* Prints the usage error `what` with h's first usage form on stderr; returns 2. */
int cdem_cmd_usage(const cdem_cli_help *h, const char *what);

/* What cdem_cmd_next_arg found. */
typedef enum {
    CDEM_CMD_ARG_USAGE = -1, /* a usage error, printed: the command returns 2 */
    CDEM_CMD_ARG_POSITIONAL, /* argv[*i] is a positional argument */
    CDEM_CMD_ARG_OPTION,     /* *opt is an option of h's table; *val its value or NULL */
} cdem_cmd_arg;

/* Reads argv[*i]: an option of h's table (its value from "=VALUE" or the next word, *i then
 * advanced past it), a positional argument ("-" alone is one), or an unknown option. */
cdem_cmd_arg cdem_cmd_next_arg(const cdem_cli_help *h, int argc, char **argv, int *i,
                               const cdem_cli_option **opt, const char **val);

/* Prints err's message on stderr, one line per line of it, each after "cdem-strain CMD: "
 * ("cdem-strain: " when cmd is NULL); a leading "CMD: " of the message is dropped (the
 * prefix names the command) and file, when given and not named by the message, goes before
 * it. Returns 1. */
int cdem_cmd_fail(const char *cmd, const char *file, const cdem_error *err);

/* 1 when text is one finite number and nothing else (strtod), stored in *out; else 0. */
int cdem_cmd_parse_number(const char *text, double *out);

/* 1 when text is one whole number in lo..hi and nothing else (strtol), stored in *out. */
int cdem_cmd_parse_int(const char *text, int lo, int hi, int *out);

/* The file name of path without its folders. */
const char *cdem_cmd_base_name(const char *path);

/* A command's text output: standard output (path NULL) or path, written through
 * path.tmp and renamed on success. */
typedef struct {
    FILE *f;         /* where to write */
    cdem_outfile of; /* the file (of.active) or nothing */
} cdem_cmd_output;

cdem_status cdem_cmd_output_open(cdem_cmd_output *o, const char *path, cdem_error *err);

/* Ends the output: flushes and closes the file, renames it when st is CDEM_OK (else
 * removes it); returns st or the first write error. Standard output is left open. */
cdem_status cdem_cmd_output_close(cdem_cmd_output *o, cdem_status st, cdem_error *err);

#endif
