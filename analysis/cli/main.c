/* cdem-strain: the command line of the analysis tool.
 *
 * The subcommands are the rows of one table (commands.h): name, summary, help, handler.
 * main only dispatches: -h/--help anywhere in a command's arguments prints that command's help
 * (stdout, exit 0) before its parser runs, so every command answers it the same way; a
 * first argument that is an existing file (not a subcommand) means "compute". Exit status:
 * 0 success, 1 error ("cdem-strain: <message>" on stderr), 2 usage error. Results go to
 * stdout (or -o FILE) so they can be redirected. */
#include "cmd_support.h"
#include "commands.h"
#include "threads.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#ifndef CDEM_VERSION
#define CDEM_VERSION "0.0.0"
#endif

int main(int argc, char **argv) {
    cdem_threads_settle_wait_policy(argv); /* idle threads sleep: threads.h */
    if (argc < 2) {
        return cdem_cmd_usage(&cdem_strain_help, "missing command");
    }
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) {
        cdem_commands_print_help(stdout);
        return CDEM_EXIT_OK;
    }
    if (!strcmp(argv[1], "-V") || !strcmp(argv[1], "--version")) {
        printf("cdem-strain %s\n", CDEM_VERSION);
        return CDEM_EXIT_OK;
    }
    const cdem_command *c = cdem_command_find(argv[1]);
    if (c) {
        if (cdem_cli_wants_help(argc, argv, 2, c->help)) {
            cdem_cli_help_print(stdout, c->help);
            return CDEM_EXIT_OK;
        }
        return c->run(argc - 1, argv + 1);
    }
    struct stat sb;
    if (argv[1][0] != '-' && stat(argv[1], &sb) == 0 && S_ISREG(sb.st_mode)) {
        const cdem_cli_help *compute = cdem_command_find("compute")->help;
        if (cdem_cli_wants_help(argc, argv, 2, compute)) {
            cdem_cli_help_print(stdout, compute);
            return CDEM_EXIT_OK;
        }
        return cdem_cmd_compute_file_first(argc - 1, argv + 1);
    }
    char msg[256];
    cdem_command_unknown(argv[1], " (and not an existing file)", msg, sizeof msg);
    return cdem_cmd_usage(&cdem_strain_help, msg);
}
