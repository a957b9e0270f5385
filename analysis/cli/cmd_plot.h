/* cmd_plot: what the calibration and evolution plot subcommands of cdem-strain share:
 *   plot-series RUN.h5 [RUN2.h5 ...] --y COLUMN [--x COLUMN] -o OUT    (cmd_plot_series.c)
 *   mohr RUN1.h5 RUN2.h5 ... | --data FILE  [-o OUT]   (Mohr-Coulomb fit; cmd_mohr.c)
 *   repose RUN.h5 ... [--increment K] [-o OUT]         (angle of repose, and the spread
 *                                                       of several packings; cmd_repose.c)
 *   voids RUN.h5 [--increment K] [--window M]          (open space and cliffs; cmd_voids.c)
 * one option parser (each command accepts the options its help lists), the time-series
 * columns, and reading a run's series or one increment. The commands return the process
 * exit code (0 ok, 1 error, 2 usage) and print their own messages ("cdem-strain <command>:
 * ..." on stderr); argv[0] is the subcommand word. cdem_cmd_plot_column extracts a named
 * time-series column (library style, no printing).
 * Ownership: nothing outlives a call. Thread safety: one call at a time per process. */
#ifndef CDEM_CMD_PLOT_H
#define CDEM_CMD_PLOT_H

#include "cdem_error.h"
#include "cli_help.h"
#include "h5format.h"

#include <stddef.h>

/* The /series columns in file order (docs/format.md): their count, and the name of column c
 * (NULL past the end). */
size_t cdem_cmd_series_column_count(void);
const char *cdem_cmd_series_column_name(size_t c);

/* out[k] = column `name` of samples[k] for k < n (names as in docs/format.md /series:
 * time, step, kinetic_energy, contacts, bonds, n_elements, net_displacement,
 * boundary_force_x, boundary_force_y, base_force_x, base_force_y, axial_strain,
 * differential_stress, sea_level, left_wall_force_x, left_wall_force_y, right_wall_force_x,
 * right_wall_force_y). *label (may be NULL) gets an axis label with unit. */
cdem_status cdem_cmd_plot_column(const cdem_series_sample *samples, size_t n, const char *name,
                                 double *out, const char **label, cdem_error *err);

#define CDEM_PLOT_MAX_FILES 64

/* The options of the plot commands (each accepts those its help lists). */
typedef struct {
    const char *cmd;                        /* subcommand word, for messages */
    const cdem_cli_help *help;              /* its help: usage errors */
    const char *files[CDEM_PLOT_MAX_FILES]; /* positional arguments */
    size_t n_files;                         /* number of positional arguments */
    const char *y, *x;                      /* --y, --x column names */
    const char *out;                        /* -o OUT */
    const char *data;                       /* --data FILE (mohr) */
    const char *increment;                  /* --increment K (repose, voids) */
    int width, height;                      /* --width, --height; 0 = default */
    int fix_x, fix_y;                       /* 1: --xrange / --yrange given */
    double window;                          /* --window M (voids); 0 = default */
    int include_poor;                       /* --include-poor-fits (repose) */
    double range[4];                        /* xmin, xmax, ymin, ymax of --xrange, --yrange */
} cdem_plot_args;

/* Fills a (a->cmd and a->help set by the caller) from argv[1..]; 0, or 2 after a usage
 * error (printed). */
int cdem_cmd_plot_parse(int argc, char **argv, cdem_plot_args *a);

/* The picture size options shared by the plots' help tables. */
#define CDEM_PLOT_WIDTH_OPTION                                                                     \
    { "--width", "N", "pixels (PNG) or points (PDF, SVG), 16 to 20000" }
#define CDEM_PLOT_HEIGHT_OPTION                                                                    \
    { "--height", "N", "as --width" }

/* Reads the whole time series of path (messages name it). */
cdem_status cdem_cmd_plot_read_series(const char *path, cdem_series_sample **smp, size_t *n,
                                      cdem_error *err);

/* cdem_cmd_plot_parse for a command of exactly one run file. */
int cdem_cmd_plot_parse_one(int argc, char **argv, cdem_plot_args *a);

/* Opens the run a->files[0] (*r, closed by the caller; NULL when it cannot be opened) and
 * loads its increment a->increment (K, last, equil, first; NULL = last) into s. */
cdem_status cdem_cmd_plot_open_increment(const cdem_plot_args *a, cdem_h5_reader **r, cdem_state *s,
                                         cdem_increment_info *info, cdem_error *err);

/* mohr's picture for cdem-strain calibrate (cmd_mohr.c): the stress-strain curves and Mohr
 * circles of n <= CDEM_PLOT_MAX_FILES biaxial runs with the envelope fitted to all of them,
 * into out (.png, .pdf, .svg). (Their peaks: cdem_mohr_read_runs, mohr.h.) */
cdem_status cdem_cmd_mohr_picture(const char *const *files, size_t n, const char *out,
                                  cdem_error *err);

/* The commands, also called directly by the tests. */
int cdem_cmd_plot_series(int argc, char **argv);
int cdem_cmd_plot_mohr(int argc, char **argv);
int cdem_cmd_plot_repose(int argc, char **argv);
int cdem_cmd_plot_voids(int argc, char **argv);

#endif
