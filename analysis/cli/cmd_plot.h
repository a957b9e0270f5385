/* cmd_plot: the calibration and evolution plot subcommands of cdem-strain:
 *   plot-series RUN.h5 [RUN2.h5 ...] --y COLUMN [--x COLUMN] -o OUT
 *   mohr RUN1.h5 RUN2.h5 ... | --data FILE  [-o OUT]   (Mohr-Coulomb fit, see mohr.h)
 *   repose RUN.h5 [--increment K] [-o OUT]             (angle of repose, see repose.h)
 *   voids RUN.h5 [--increment K] [--window M]          (open space and cliffs, see voids.h)
 * Each returns the process exit code (0 ok, 1 error, 2 usage) and prints its own messages
 * ("cdem-strain <command>: ..." on stderr); argv[0] is the subcommand word.
 * cdem_cmd_plot_column extracts a named time-series column (library style, no printing).
 * Ownership: nothing outlives a call. Thread safety: one call at a time per process. */
#ifndef CDEM_CMD_PLOT_H
#define CDEM_CMD_PLOT_H

#include "cdem_error.h"
#include "cli_help.h"
#include "h5format.h"

#include <stddef.h>

/* out[k] = column `name` of samples[k] for k < n (names as in docs/format.md /series:
 * time, step, kinetic_energy, contacts, bonds, n_elements, net_displacement,
 * boundary_force_x, boundary_force_y, base_force_x, base_force_y, axial_strain,
 * differential_stress, sea_level). *label (may be NULL) gets an axis label with unit. */
cdem_status cdem_cmd_plot_column(const cdem_series_sample *samples, size_t n, const char *name,
                                 double *out, const char **label, cdem_error *err);

/* Usage, description and options of each (--help, man page, completion). */
extern const cdem_cli_help cdem_cmd_plot_series_help;
extern const cdem_cli_help cdem_cmd_mohr_help;
extern const cdem_cli_help cdem_cmd_repose_help;
extern const cdem_cli_help cdem_cmd_voids_help;

int cdem_cmd_plot_series(int argc, char **argv);
int cdem_cmd_plot_mohr(int argc, char **argv);
int cdem_cmd_plot_repose(int argc, char **argv);
int cdem_cmd_plot_voids(int argc, char **argv);

#endif
