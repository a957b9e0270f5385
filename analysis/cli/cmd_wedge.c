/* cmd_wedge: see cmd_wedge.h. */
#include "cmd_wedge.h"

#include "analysis.h"
#include "run_file.h"
#include "csvtable.h"
#include "plot.h"
#include "render.h"
#include "wedge.h"

#include <cairo.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_CSV_FILES 32
#define MAX_Y_COLUMNS 16

/* synopsis is the first usage form of the command's help */
static int usage(const char *cmd, const char *what, const char *synopsis) {
    (void)synopsis;
    cdem_cli_usage_print(
        stderr, !strcmp(cmd, "wedge") ? &cdem_cmd_wedge_help : &cdem_cmd_plot_csv_help, what);
    return 2;
}

static int fail(const char *cmd, const cdem_error *err) {
    const char *m = err->msg[0] ? err->msg : "unknown error";
    const size_t len = strlen(cmd);
    if (!strncmp(m, cmd, len) && m[len] == ':' && m[len + 1] == ' ')
        m += len + 2; /* "wedge: ..." from the library: the command already names it */
    fprintf(stderr, "cdem-strain %s: %s\n", cmd, m);
    return 1;
}

/* fail, naming the run file the command read when the message does not. */
static int fail_on(const char *cmd, const char *file, const cdem_error *err) {
    if (!file || !err->msg[0] || strstr(err->msg, file))
        return fail(cmd, err);
    fprintf(stderr, "cdem-strain %s: %s: %s\n", cmd, file, err->msg);
    return 1;
}

/* Value of option argv[*i] ("--opt VALUE" or "--opt=VALUE") when it is `flag`; NULL
 * otherwise; *missing = 1 when the flag has no value. */
static const char *opt_value(int argc, char **argv, int *i, const char *flag, int *missing) {
    size_t len = strlen(flag);
    if (strncmp(argv[*i], flag, len) != 0 || (argv[*i][len] && argv[*i][len] != '='))
        return NULL;
    if (argv[*i][len] == '=')
        return argv[*i] + len + 1;
    if (*i + 1 >= argc) {
        *missing = 1;
        return NULL;
    }
    return argv[++*i];
}

/* ---------------------------------------------------------------- wedge */
static const char wedge_synopsis[] = "RUN.h5 [-o OUT.csv] [--increment K|last|all] [--threshold M]";
static const char *const wedge_forms[] = {wedge_synopsis, NULL};
static const cdem_cli_option wedge_options[] = {
    {"-o, --output", "OUT.csv", "output file (default: standard output)"},
    {"--increment", "K|last|equil|all",
     "one increment, or all (default) from the end of "
     "equilibration on"},
    {"--threshold", "M", "deformed-zone threshold in m (default: the mean element diameter)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_wedge_help = {
    .program = "cdem-strain wedge",
    .forms = wedge_forms,
    .about = "Accretionary-wedge measurements per increment from the end of equilibration, as "
             "CSV: shortening, height, length, taper, area change and the wall forces "
             "(columns and definitions in docs/analysis.md, \"Wedge\").",
    .options = wedge_options,
};

int cdem_cmd_wedge(int argc, char **argv) {
    const char *cmd = "wedge", *file = NULL, *out = NULL, *inc = "all", *thr = NULL;
    for (int i = 1; i < argc; i++) {
        int missing = 0;
        const char *v;
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            cdem_cli_help_print(stdout, &cdem_cmd_wedge_help);
            return 0;
        }
        if ((v = opt_value(argc, argv, &i, "-o", &missing)) ||
            (v = opt_value(argc, argv, &i, "--output", &missing)))
            out = v;
        else if ((v = opt_value(argc, argv, &i, "--increment", &missing)))
            inc = v;
        else if ((v = opt_value(argc, argv, &i, "--threshold", &missing)))
            thr = v;
        else if (missing)
            return usage(cmd, "an option needs a value", wedge_synopsis);
        else if (argv[i][0] == '-' && argv[i][1]) {
            char msg[160];
            snprintf(msg, sizeof msg, "unknown option '%.100s'", argv[i]);
            return usage(cmd, msg, wedge_synopsis);
        } else if (!file)
            file = argv[i];
        else
            return usage(cmd, "need exactly one run file (RUN.h5)", wedge_synopsis);
        if (missing)
            return usage(cmd, "an option needs a value", wedge_synopsis);
    }
    if (!file)
        return usage(cmd, "missing the run file (RUN.h5)", wedge_synopsis);
    cdem_wedge_options opt = {0};
    if (thr) {
        char *end;
        errno = 0;
        opt.threshold = strtod(thr, &end);
        if (errno || end == thr || *end || !isfinite(opt.threshold) || opt.threshold < 0)
            return usage(cmd, "--threshold must be a length in m >= 0 (0 = default)",
                         wedge_synopsis);
    }
    cdem_error err;
    cdem_analysis *a;
    if (cdem_analysis_open(file, &a, &err) != CDEM_OK)
        return fail(cmd, &err);
    size_t first = 0, last = cdem_analysis_count(a) - 1;
    cdem_status st = CDEM_OK;
    if (strcmp(inc, "all") != 0) {
        st = cdem_analysis_find(a, inc, &first, &err);
        last = first;
    }
    if (cdem_analysis_params(a)->mode == CDEM_MODE_DETACHMENT &&
        cdem_analysis_params(a)->detachment_walls == CDEM_WALLS_BOTH)
        fprintf(stderr,
                "cdem-strain wedge: note: %s moves both walls: the wedge is measured from "
                "the right wall, and the wall force columns are the sum over both walls "
                "(their x components cancel)\n",
                file);
    cdem_wedge_row *rows = NULL;
    size_t n = 0;
    cdem_wedge_ref ref;
    if (st == CDEM_OK)
        st = cdem_wedge_analyse(a, &opt, first, last, &rows, &n, &ref, &err);
    if (st == CDEM_OK && !out)
        st = cdem_wedge_write_csv(stdout, rows, n, &err);
    else if (st == CDEM_OK) {
        /* written to OUT.tmp, renamed on success (outfile.h) */
        cdem_outfile of;
        st = cdem_outfile_begin(&of, out, &err);
        FILE *f = NULL;
        if (st == CDEM_OK && !(f = fopen(of.tmp, "w")))
            st = CDEM_FAIL(&err, CDEM_ERR_IO, "cannot create %s: %s", out, strerror(errno));
        if (st == CDEM_OK)
            st = cdem_wedge_write_csv(f, rows, n, &err);
        if (f && fclose(f) != 0 && st == CDEM_OK)
            st = CDEM_FAIL(&err, CDEM_ERR_IO, "error writing %s", out);
        st = cdem_outfile_end(&of, st, &err); /* nothing to do if begin failed */
    }
    if (st == CDEM_OK && n > 0) {
        const cdem_wedge_row *r = &rows[n - 1];
        fprintf(stderr,
                "cdem-strain wedge: reference increment %d: length %.6g m, thickness %.6g m, "
                "columns %.4g m, threshold %.4g m\n"
                "cdem-strain wedge: increment %d: shortening %.6g m (%.3g %%), height %.6g m, "
                "length %.6g m, taper %.3g deg, area change %.3g %%\n",
                (int)cdem_analysis_info(a, cdem_analysis_equil_index(a))->number, ref.length0,
                ref.thickness0, ref.column_width, ref.threshold, r->number, r->shortening,
                r->shortening_percent, r->height, r->length, r->taper_deg, r->area_change_percent);
    }
    free(rows);
    cdem_analysis_close(a);
    return st == CDEM_OK ? 0 : fail_on(cmd, file, &err);
}

/* ---------------------------------------------------------------- plot-csv */
static const char plot_csv_synopsis[] =
    "A.csv [B.csv ...] --x COLUMN --y COLUMN[,COLUMN...] -o OUT.png|.pdf|.svg [--labels "
    "L1,L2,...] [--columns N] [--legend K] [--width N] [--height N]";
static const char *const plot_csv_forms[] = {plot_csv_synopsis, NULL};
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
const cdem_cli_help cdem_cmd_plot_csv_help = {
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

cdem_status cdem_cmd_plot_csv_figure(const char *const *files, const char *const *labels,
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
            ser[j][f] = (cdem_plot_series){.x = xs[f],
                                           .y = ys[f][j],
                                           .n = tab[f].n_rows,
                                           .label = names[f],
                                           .colour = cdem_plot_palette(f),
                                           .line = 1};
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

static int parse_int_range(const char *text, int lo, int hi, int *out) {
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (errno || end == text || *end || v < lo || v > hi)
        return 0;
    *out = (int)v;
    return 1;
}

int cdem_cmd_plot_csv(int argc, char **argv) {
    const char *cmd = "plot-csv", *x = NULL, *y = NULL, *out = NULL, *labels = NULL;
    const char *files[MAX_CSV_FILES];
    size_t n_files = 0;
    int ncols = 3, legend = 1, width = 0, height = 0;
    for (int i = 1; i < argc; i++) {
        int missing = 0;
        const char *v;
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            cdem_cli_help_print(stdout, &cdem_cmd_plot_csv_help);
            return 0;
        }
        if ((v = opt_value(argc, argv, &i, "--x", &missing)))
            x = v;
        else if ((v = opt_value(argc, argv, &i, "--y", &missing)))
            y = v;
        else if ((v = opt_value(argc, argv, &i, "-o", &missing)) ||
                 (v = opt_value(argc, argv, &i, "--output", &missing)))
            out = v;
        else if ((v = opt_value(argc, argv, &i, "--labels", &missing)))
            labels = v;
        else if ((v = opt_value(argc, argv, &i, "--legend", &missing))) {
            if (!parse_int_range(v, 0, MAX_Y_COLUMNS, &legend))
                return usage(cmd, "--legend must be a panel number from 1 to 16 (0 = no legend)",
                             plot_csv_synopsis);
        } else if ((v = opt_value(argc, argv, &i, "--columns", &missing))) {
            if (!parse_int_range(v, 1, MAX_Y_COLUMNS, &ncols))
                return usage(cmd, "--columns must be a whole number from 1 to 16",
                             plot_csv_synopsis);
        } else if ((v = opt_value(argc, argv, &i, "--width", &missing))) {
            if (!parse_int_range(v, 16, CDEM_RENDER_MAX_SIZE, &width))
                return usage(cmd, "--width must be a whole number from 16 to 20000",
                             plot_csv_synopsis);
        } else if ((v = opt_value(argc, argv, &i, "--height", &missing))) {
            if (!parse_int_range(v, 16, CDEM_RENDER_MAX_SIZE, &height))
                return usage(cmd, "--height must be a whole number from 16 to 20000",
                             plot_csv_synopsis);
        } else if (missing)
            return usage(cmd, "an option needs a value", plot_csv_synopsis);
        else if (argv[i][0] == '-' && argv[i][1]) {
            char msg[160];
            snprintf(msg, sizeof msg, "unknown option '%.100s'", argv[i]);
            return usage(cmd, msg, plot_csv_synopsis);
        } else if (n_files < MAX_CSV_FILES)
            files[n_files++] = argv[i];
        else
            return usage(cmd, "too many CSV files (at most 32)", plot_csv_synopsis);
        if (missing)
            return usage(cmd, "an option needs a value", plot_csv_synopsis);
    }
    if (!n_files)
        return usage(cmd, "missing the CSV file(s)", plot_csv_synopsis);
    if (!x || !y)
        return usage(cmd, "missing --x COLUMN or --y COLUMN[,COLUMN...]", plot_csv_synopsis);
    if (!out)
        return usage(cmd, "missing -o OUT.png|.pdf|.svg", plot_csv_synopsis);
    char ybuf[1024], lbuf[2048];
    snprintf(ybuf, sizeof ybuf, "%s", y);
    const char *ycols[MAX_Y_COLUMNS], *lab[MAX_CSV_FILES];
    size_t ny = split_commas(ybuf, ycols, MAX_Y_COLUMNS);
    if (ny > MAX_Y_COLUMNS)
        return usage(cmd, "at most 16 --y columns", plot_csv_synopsis);
    if (labels) {
        snprintf(lbuf, sizeof lbuf, "%s", labels);
        if (split_commas(lbuf, lab, MAX_CSV_FILES) != n_files)
            return usage(cmd, "--labels must give one label per CSV file (comma-separated)",
                         plot_csv_synopsis);
    }
    const size_t nc = (size_t)ncols < ny ? (size_t)ncols : ny;
    if (!width)
        width = (int)(500 * nc);
    if (!height)
        height = (int)(380 * ((ny + nc - 1) / nc));
    cdem_error err;
    if (cdem_cmd_plot_csv_figure(files, labels ? lab : NULL, n_files, x, ycols, ny, ncols, legend,
                                 width, height, out, &err) != CDEM_OK)
        return fail(cmd, &err);
    return 0;
}
