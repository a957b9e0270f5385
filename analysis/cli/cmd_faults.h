/* cmd_faults: the faults subcommand of cdem-strain:
 *   faults RUN.h5 [--increment K|last|equil|first] [--quantity NAME] [--threshold V]
 *                 [--bin M] [--min-rows N] [-o OUT.csv]
 *       fault zones picked from a strain field (faults.h): one CSV row per zone with where it
 *       reaches up and down, its dip and dip direction; a summary on standard error.
 * Returns the process exit code (0 ok, 1 error, 2 usage) and prints its own messages
 * ("cdem-strain faults: ..." on stderr); argv[0] is the subcommand word.
 * Ownership: nothing outlives a call. Thread safety: one call at a time per process. */
#ifndef CDEM_CMD_FAULTS_H
#define CDEM_CMD_FAULTS_H

#include "cli_help.h"

extern const cdem_cli_help cdem_cmd_faults_help;

int cdem_cmd_faults(int argc, char **argv);

#endif
