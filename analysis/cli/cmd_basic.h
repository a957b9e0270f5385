/* cmd_basic: the simple subcommands of cdem-strain, each a function of the command line
 * (argv[0] is the subcommand word) returning the exit code (0 success, 1 error, 2 usage
 * error) and printing its own results and messages ("cdem-strain: ..." on stderr):
 *   info RUN.h5                  summary, stop reason, increments
 *   compute RUN.h5 ...           per-element values of a quantity (CSV or HDF5)
 *   element, limits              one element's values; colour-bar limits
 *   export-sspx, export-biaxial  text exports (docs/formats-text.md)
 *   import-cdem2d DIR -o OUT.h5  a cdem2D folder into a cdem file
 *   quantities                   the quantity names
 *   xdmf FILE.h5                 (re)writes the XDMF sidecar of a run or compute file
 *   series RUN.h5                the time series as CSV
 * Each has a help description (cli_help.h), which is also the table its parser accepts.
 * Ownership: nothing outlives a call. Thread safety: one call at a time per process. */
#ifndef CDEM_CMD_BASIC_H
#define CDEM_CMD_BASIC_H

#include "cli_help.h"

int cdem_cmd_info(int argc, char **argv);
int cdem_cmd_compute(int argc, char **argv);
int cdem_cmd_element(int argc, char **argv);
int cdem_cmd_limits(int argc, char **argv);
int cdem_cmd_export_sspx(int argc, char **argv);
int cdem_cmd_export_biaxial(int argc, char **argv);
int cdem_cmd_import_cdem2d(int argc, char **argv);
int cdem_cmd_quantities(int argc, char **argv);
int cdem_cmd_xdmf(int argc, char **argv);
int cdem_cmd_series(int argc, char **argv);

/* "cdem-strain RUN.h5 --increment K --quantity NAME": compute with argv[0] the run file. */
int cdem_cmd_compute_file_first(int argc, char **argv);

extern const cdem_cli_help cdem_cmd_info_help;
extern const cdem_cli_help cdem_cmd_compute_help;
extern const cdem_cli_help cdem_cmd_element_help;
extern const cdem_cli_help cdem_cmd_limits_help;
extern const cdem_cli_help cdem_cmd_export_sspx_help;
extern const cdem_cli_help cdem_cmd_export_biaxial_help;
extern const cdem_cli_help cdem_cmd_import_cdem2d_help;
extern const cdem_cli_help cdem_cmd_quantities_help;
extern const cdem_cli_help cdem_cmd_xdmf_help;
extern const cdem_cli_help cdem_cmd_series_help;

#endif
