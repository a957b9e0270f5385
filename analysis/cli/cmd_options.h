/* cmd_options: the options of cdem-strain's simple commands (info, compute, element,
 * limits, series, export-sspx, export-biaxial, import-cdem2d, xdmf, quantities). They share
 * one parser that accepts exactly the options of the command's help table (cli_help.h), so
 * --help, the man page, the bash completion and the parser cannot disagree; each option's
 * value lands in the field of its long name. A simple command is a function of the parsed
 * options (cmd_NAME.c) and its help.
 * Ownership: the fields point into argv. Thread safety: one command at a time. */
#ifndef CDEM_CMD_OPTIONS_H
#define CDEM_CMD_OPTIONS_H

#include "analysis.h"
#include "cmd_support.h"
#include "commands.h"

/* Parsed options shared by the simple commands (each accepts the ones its help lists). */
typedef struct {
    const cdem_cli_help *help; /* the command's help: its usage errors */
    const char *file;          /* positional: the run file (or cdem2D folder for import) */
    const char *dir;           /* second positional: output directory (export-sspx) */
    const char *increment;     /* --increment K|last|equil|first|all */
    const char *increments;    /* --increments A-B */
    const char *quantity;      /* --quantity NAME */
    const char *format;        /* --format csv|h5 */
    const char *out;           /* -o OUT */
    const char *prefix;        /* --prefix P */
    const char *element;       /* --element ID */
    int xdmf2;                 /* --xdmf2 */
    int json;                  /* --json */
} cdem_cmd_options;

/* Parses argv[first..] against h's options (positionals: 1 = the file, 2 = the file and a
 * folder) and runs fn on them; returns fn's exit status, or 2 after a usage error. */
int cdem_cmd_options_run(int argc, char **argv, int first, const cdem_cli_help *h, int positionals,
                         int (*fn)(const cdem_cmd_options *));

/* The end of a simple command's file cmd_ID.c, after its function FN and its help `help`:
 * the handler and the command's row (commands.h) for the subcommand WORD. POSITIONALS as
 * for cdem_cmd_options_run. */
#define CDEM_SIMPLE_COMMAND(ID, WORD, SUMMARY, POSITIONALS, FN)                                    \
    static int run(int argc, char **argv) {                                                        \
        return cdem_cmd_options_run(argc, argv, 1, &help, POSITIONALS, FN);                        \
    }                                                                                              \
    const cdem_command cdem_command_##ID = {WORD, SUMMARY, &help, run}

/* Opens o->file as an analysis context (*a, closed by the caller); 0, or the exit status
 * of the usage error or failure it printed. */
int cdem_cmd_open_run(const cdem_cmd_options *o, cdem_analysis **a);

/* The quantity o->quantity (*q) and then, as cdem_cmd_open_run, the run (*a). */
int cdem_cmd_open_run_quantity(const cdem_cmd_options *o, const cdem_quantity **q,
                               cdem_analysis **a);

#endif
