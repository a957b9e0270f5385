/* cmd_wedge: the wedge and plot-csv subcommands of cdem-strain:
 *   wedge RUN.h5 [-o OUT.csv] [--increment K|last|all] [--threshold M]
 *       accretionary-wedge measurements per increment (wedge.h, docs/analysis.md "Wedge")
 *   plot-csv A.csv [B.csv ...] --x COL --y COL[,COL...] -o OUT.png|.pdf|.svg
 *       [--labels L1,L2,...] [--columns N] [--legend K] [--width N] [--height N]
 *       one panel per y column, one curve per file, panels in a grid of N columns
 * Each returns the process exit code (0 ok, 1 error, 2 usage) and prints its own messages
 * ("cdem-strain <command>: ..." on stderr); argv[0] is the subcommand word.
 * cdem_cmd_plot_csv_figure is the library part of plot-csv (no printing).
 * Ownership: nothing outlives a call. Thread safety: one call at a time per process. */
#ifndef CDEM_CMD_WEDGE_H
#define CDEM_CMD_WEDGE_H

#include "cdem_error.h"
#include "cli_help.h"

#include <stddef.h>

/* Draws the plot-csv figure: n_files CSV files (labels[i] or the file's base name without
 * .csv when labels is NULL), x column xcol, one panel per name in ycols (n_y >= 1), grid of
 * ncols panel columns, the legend on panel `legend` (1-based; 0 = no legend), width x height
 * image written to out (.png/.pdf/.svg). */
cdem_status cdem_cmd_plot_csv_figure(const char *const *files, const char *const *labels,
                                     size_t n_files, const char *xcol, const char *const *ycols,
                                     size_t n_y, int ncols, int legend, int width, int height,
                                     const char *out, cdem_error *err);

/* Usage, description and options of each (--help, man page, completion). */
extern const cdem_cli_help cdem_cmd_wedge_help;
extern const cdem_cli_help cdem_cmd_plot_csv_help;

int cdem_cmd_wedge(int argc, char **argv);
int cdem_cmd_plot_csv(int argc, char **argv);

#endif
