/* cmd_plot_csv: the plot-csv subcommand of cdem-strain:
 *   plot-csv A.csv [B.csv ...] --x COL --y COL[,COL...] -o OUT.png|.pdf|.svg
 *       [--labels L1,L2,...] [--columns N] [--legend K] [--width N] [--height N]
 *       one panel per y column, one curve per file, panels in a grid of N columns. */
#include "cmd_support.h"
#include "commands.h"
#include "csvtable.h"
#include "plot.h"
#include "render.h"

#include <cairo.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_CSV_FILES 32
#define MAX_Y_COLUMNS 16

static const char *const plot_csv_forms[] = {
    "A.csv [B.csv ...] --x COLUMN --y COLUMN[,COLUMN...] -o OUT.png|.pdf|.svg [--labels "
    "L1,L2,...] [--columns N] [--legend K] [--width N] [--height N]",
    NULL};
static const cdem_cli_option plot_csv_options[] = {
    {"--x", "COLUMN", "the x column (by its header name)"},
    {"--y", "COLUMN[,COLUMN...]", "one panel per column (at most 16)"},
    {"-o, --output", "OUT.png|.pdf|.svg", "the picture"},
    {"--labels", "L1,L2,...", "one legend label per CSV file (default: the file names)"},
    {"--columns", "N", "panels across (default 3)"},
    {"--legend", "K", "the panel that holds the legend, 1 to 16 (default 1; 0 = none)"},
    {"--width", "N", "pixels (PNG) or points (PDF, SVG), 16 to 20000"},
    {"--height", "N", "as --width"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain plot-csv",
    .forms = plot_csv_forms,
    .about = "Curves of CSV columns (e.g. of several wedge tables), one curve per file and one "
             "panel per --y column in a grid.",
    .options = plot_csv_options,
};

/* Axis labels of the wedge table's columns; other columns are labelled by their name. */
static const struct {
    const char *name;  /* CSV column name */
    const char *label; /* axis label with unit */
} known_labels[] = {
    {"shortening_m", "Shortening (m)"},
    {"shortening_percent", "Shortening (%)"},
    {"height_m", "Wedge height (m)"},
    {"length_m", "Wedge length (m)"},
    {"length_thickened_m", "Thickened length (m)"},
    {"taper_deg", "Surface taper (deg)"},
    {"area_change_m2", "Area change (m^2)"},
    {"area_change_percent", "Area change (%)"},
    {"wall_force_x_N", "Wall force x (N)"},
    {"wall_force_y_N", "Wall force y (N)"},
    {"base_force_x_N", "Base force x (N)"},
    {"base_force_y_N", "Base force y (N)"},
    {"left_wall_force_x_N", "Left wall force x (N)"},
    {"left_wall_force_y_N", "Left wall force y (N)"},
    {"right_wall_force_x_N", "Right wall force x (N)"},
    {"right_wall_force_y_N", "Right wall force y (N)"},
};

static const char *label_of(const char *name) {
    for (size_t i = 0; i < sizeof known_labels / sizeof known_labels[0]; i++)
        if (!strcmp(name, known_labels[i].name))
            return known_labels[i].label;
    return name;
}

/* Base name of path without its directory and a trailing ".csv", into buf. */
static void base_label(const char *path, char *buf, size_t n) {
    const char *b = strrchr(path, '/');
    snprintf(buf, n, "%s", b ? b + 1 : path);
    size_t len = strlen(buf);
    if (len > 4 && !strcmp(buf + len - 4, ".csv"))
        buf[len - 4] = '\0';
}

/* Draws the figure: n_files CSV files (labels[i] or the file's base name without .csv when
 * labels is NULL), x column xcol, one panel per name in ycols (n_y >= 1), grid of ncols
 * panel columns, the legend on panel `legend` (1-based; 0 = no legend), width x height
 * image written to out (.png/.pdf/.svg). */
static cdem_status plot_csv_figure(const char *const *files, const char *const *labels,
                                   size_t n_files, const char *xcol, const char *const *ycols,
                                   size_t n_y, int ncols, int legend, int width, int height,
                                   const char *out, cdem_error *err) {
    if (!files || !xcol || !ycols || !out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "plot-csv: NULL argument");
    if (n_files < 1 || n_files > MAX_CSV_FILES)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "plot-csv: %zu files: give 1 to %d", n_files,
                         MAX_CSV_FILES);
    if (n_y < 1 || n_y > MAX_Y_COLUMNS)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "plot-csv: %zu y columns: give 1 to %d", n_y,
                         MAX_Y_COLUMNS);
    if (ncols < 1 || ncols > MAX_Y_COLUMNS)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "plot-csv: --columns %d: must be 1 to %d", ncols,
                         MAX_Y_COLUMNS);
    if (width < 16 || width > CDEM_RENDER_MAX_SIZE || height < 16 || height > CDEM_RENDER_MAX_SIZE)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "plot-csv: image size %d x %d: each side must be in "
                         "16..%d",
                         width, height, CDEM_RENDER_MAX_SIZE);
    cdem_render_format fmt;
    CDEM_TRY(cdem_render_format_from_path(out, &fmt, err));
    cdem_csvtable tab[MAX_CSV_FILES];
    memset(tab, 0, sizeof tab);
    double *xs[MAX_CSV_FILES] = {0}, *ys[MAX_CSV_FILES][MAX_Y_COLUMNS];
    memset(ys, 0, sizeof ys);
    char names[MAX_CSV_FILES][128];
    static const size_t none = (size_t)-1;
    cdem_status st = CDEM_OK;
    for (size_t f = 0; f < n_files && st == CDEM_OK; f++) {
        st = cdem_csvtable_read(files[f], &tab[f], err);
        size_t cx = none;
        if (st == CDEM_OK)
            st = cdem_csvtable_find(&tab[f], xcol, files[f], &cx, err);
        const size_t nr = tab[f].n_rows ? tab[f].n_rows : 1;
        if (st == CDEM_OK && !(xs[f] = malloc(nr * sizeof(double))))
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "plot-csv: no memory for %zu rows", nr);
        if (st == CDEM_OK)
            cdem_csvtable_column(&tab[f], cx, xs[f]);
        for (size_t j = 0; j < n_y && st == CDEM_OK; j++) {
            size_t cy = none;
            st = cdem_csvtable_find(&tab[f], ycols[j], files[f], &cy, err);
            if (st == CDEM_OK && !(ys[f][j] = malloc(nr * sizeof(double))))
                st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "plot-csv: no memory for %zu rows", nr);
            if (st == CDEM_OK)
                cdem_csvtable_column(&tab[f], cy, ys[f][j]);
        }
        if (labels && labels[f])
            snprintf(names[f], sizeof names[f], "%s", labels[f]);
        else
            base_label(files[f], names[f], sizeof names[f]);
    }
    cdem_plot_series ser[MAX_Y_COLUMNS][MAX_CSV_FILES];
    cdem_plot panels[MAX_Y_COLUMNS];
    memset(ser, 0, sizeof ser);
    memset(panels, 0, sizeof panels);
    for (size_t j = 0; j < n_y && st == CDEM_OK; j++) {
        for (size_t f = 0; f < n_files; f++)
            ser[j][f] = (cdem_plot_series){
                .x = xs[f], .y = ys[f][j], .n = tab[f].n_rows, .label = names[f], .line = 1};
        panels[j] = (cdem_plot){.xlabel = label_of(xcol),
                                .ylabel = label_of(ycols[j]),
                                .series = ser[j],
                                .n_series = n_files,
                                .no_legend = (int)j + 1 != legend}; /* one legend */
    }
    if (st == CDEM_OK) {
        const size_t nc = (size_t)ncols < n_y ? (size_t)ncols : n_y;
        const size_t nrow = (n_y + nc - 1) / nc;
        /* written to OUT.tmp, renamed on success (outfile.h) */
        cdem_render_target t;
        st = cdem_render_target_open(&t, out, fmt, width, height, "plot-csv", err);
        if (st == CDEM_OK) {
            cairo_t *cr = cairo_create(t.surf);
            cairo_set_source_rgb(cr, 1, 1, 1);
            cairo_paint(cr);
            const double pw = (double)width / (double)nc, ph = (double)height / (double)nrow;
            for (size_t j = 0; j < n_y && st == CDEM_OK; j++)
                st = cdem_plot_draw(cr, &panels[j], (double)(j % nc) * pw, (double)(j / nc) * ph,
                                    pw, ph, NULL, err);
            cairo_destroy(cr);
            st = cdem_render_target_close(&t, st, err);
        }
    }
    for (size_t f = 0; f < n_files; f++) {
        free(xs[f]);
        for (size_t j = 0; j < n_y; j++)
            free(ys[f][j]);
        cdem_csvtable_free(&tab[f]);
    }
    return st;
}

/* Splits text at commas into at most max parts of buf (modified in place). */
static size_t split_commas(char *buf, const char **parts, size_t max) {
    size_t n = 0;
    char *p = buf;
    while (p && n < max + 1) {
        char *c = strchr(p, ',');
        if (c)
            *c = '\0';
        if (n < max)
            parts[n] = p;
        n++;
        p = c ? c + 1 : NULL;
    }
    return n;
}

static int run(int argc, char **argv) {
    const char *x = NULL, *y = NULL, *out = NULL, *labels = NULL;
    const char *files[MAX_CSV_FILES];
    size_t n_files = 0;
    int ncols = 3, legend = 1, width = 0, height = 0;
    for (int i = 1; i < argc; i++) {
        const cdem_cli_option *o;
        const char *v;
        const cdem_cmd_arg kind = cdem_cmd_next_arg(&help, argc, argv, &i, &o, &v);
        if (kind == CDEM_CMD_ARG_USAGE)
            return CDEM_EXIT_USAGE;
        if (kind == CDEM_CMD_ARG_POSITIONAL) {
            if (n_files == MAX_CSV_FILES)
                return cdem_cmd_usage(&help, "too many CSV files (at most 32)");
            files[n_files++] = argv[i];
        } else if (cdem_cli_option_is(o, "--x"))
            x = v;
        else if (cdem_cli_option_is(o, "--y"))
            y = v;
        else if (cdem_cli_option_is(o, "--output"))
            out = v;
        else if (cdem_cli_option_is(o, "--labels"))
            labels = v;
        else if (cdem_cli_option_is(o, "--legend")) {
            if (!cdem_cmd_parse_int(v, 0, MAX_Y_COLUMNS, &legend))
                return cdem_cmd_usage(
                    &help, "--legend must be a panel number from 1 to 16 (0 = no legend)");
        } else if (cdem_cli_option_is(o, "--columns")) {
            if (!cdem_cmd_parse_int(v, 1, MAX_Y_COLUMNS, &ncols))
                return cdem_cmd_usage(&help, "--columns must be a whole number from 1 to 16");
        } else if (cdem_cli_option_is(o, "--width")) {
            if (!cdem_cmd_parse_int(v, 16, CDEM_RENDER_MAX_SIZE, &width))
                return cdem_cmd_usage(&help, "--width must be a whole number from 16 to 20000");
        } else if (!cdem_cmd_parse_int(v, 16, CDEM_RENDER_MAX_SIZE, &height)) /* --height */
            return cdem_cmd_usage(&help, "--height must be a whole number from 16 to 20000");
    }
    if (!n_files)
        return cdem_cmd_usage(&help, "missing the CSV file(s)");
    if (!x || !y)
        return cdem_cmd_usage(&help, "missing --x COLUMN or --y COLUMN[,COLUMN...]");
    if (!out)
        return cdem_cmd_usage(&help, "missing -o OUT.png|.pdf|.svg");
    char ybuf[1024], lbuf[2048];
    snprintf(ybuf, sizeof ybuf, "%s", y);
    const char *ycols[MAX_Y_COLUMNS], *lab[MAX_CSV_FILES];
    size_t ny = split_commas(ybuf, ycols, MAX_Y_COLUMNS);
    if (ny > MAX_Y_COLUMNS)
        return cdem_cmd_usage(&help, "at most 16 --y columns");
    if (labels) {
        snprintf(lbuf, sizeof lbuf, "%s", labels);
        if (split_commas(lbuf, lab, MAX_CSV_FILES) != n_files)
            return cdem_cmd_usage(&help,
                                  "--labels must give one label per CSV file (comma-separated)");
    }
    const size_t nc = (size_t)ncols < ny ? (size_t)ncols : ny;
    if (!width)
        width = (int)(500 * nc);
    if (!height)
        height = (int)(380 * ((ny + nc - 1) / nc));
    cdem_error err;
    if (plot_csv_figure(files, labels ? lab : NULL, n_files, x, ycols, ny, ncols, legend, width,
                        height, out, &err) != CDEM_OK)
        return cdem_cmd_fail("plot-csv", NULL, &err);
    return 0;
}

const cdem_command cdem_command_plot_csv = {
    "plot-csv", "curves of CSV columns, several files per panel", &help, run};
