/* cmd_plot: see cmd_plot.h. */
#include "cmd_plot.h"

#include "cmd_support.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The /series columns in file order (docs/format.md): the one list of the analysis side,
 * used by plot-series and series. Integer columns are read as int64. */
typedef struct {
    const char *name;  /* column name */
    const char *label; /* axis label with unit */
    size_t offset;     /* offsetof(cdem_series_sample, the column) */
    int is_int;        /* 1: int64 in the sample */
} column_def;

#define COL(f, label)                                                                              \
    { #f, label, offsetof(cdem_series_sample, f), 0 }
#define ICOL(f, label)                                                                             \
    { #f, label, offsetof(cdem_series_sample, f), 1 }
static const column_def columns[] = {
    ICOL(step, "Time step"),
    COL(time, "Time (s)"),
    COL(kinetic_energy, "Kinetic energy (J/m)"),
    ICOL(contacts, "Contacts"),
    ICOL(bonds, "Bonds"),
    ICOL(n_elements, "Elements"),
    COL(net_displacement, "Net displacement (m)"),
    COL(boundary_force_x, "Boundary force x (N)"),
    COL(boundary_force_y, "Boundary force y (N)"),
    COL(base_force_x, "Base force x (N)"),
    COL(base_force_y, "Base force y (N)"),
    COL(axial_strain, "Axial strain"),
    COL(differential_stress, "Differential stress (N/m)"),
    COL(sea_level, "Sea level (m)"),
    COL(left_wall_force_x, "Left wall force x (N)"),
    COL(left_wall_force_y, "Left wall force y (N)"),
    COL(right_wall_force_x, "Right wall force x (N)"),
    COL(right_wall_force_y, "Right wall force y (N)"),
/* the processes' own columns, labelled by their rows (common/processes/<id>.h) */
#define CDEM_PROCESS_SERIES(name, unit, lo, hi, label) COL(name, label),
#include "processes.def"
#undef CDEM_PROCESS_SERIES
};
#undef COL
#undef ICOL
#define N_COLUMNS (sizeof columns / sizeof columns[0])

static double column_value(const cdem_series_sample *s, size_t c) {
    const char *p = (const char *)s + columns[c].offset;
    if (columns[c].is_int) {
        int64_t v;
        memcpy(&v, p, sizeof v);
        return (double)v;
    }
    double v;
    memcpy(&v, p, sizeof v);
    return v;
}

size_t cdem_cmd_series_column_count(void) {
    return N_COLUMNS;
}

const char *cdem_cmd_series_column_name(size_t c) {
    return c < N_COLUMNS ? columns[c].name : NULL;
}

cdem_status cdem_cmd_plot_column(const cdem_series_sample *samples, size_t n, const char *name,
                                 double *out, const char **label, cdem_error *err) {
    for (size_t c = 0; c < N_COLUMNS; c++)
        if (name && !strcmp(name, columns[c].name)) {
            for (size_t k = 0; k < n; k++)
                out[k] = column_value(&samples[k], c);
            if (label)
                *label = columns[c].label;
            return CDEM_OK;
        }
    char list[400] = "";
    for (size_t c = 0; c < N_COLUMNS; c++) {
        strncat(list, columns[c].name, sizeof list - strlen(list) - 1);
        if (c + 1 < N_COLUMNS)
            strncat(list, ", ", sizeof list - strlen(list) - 1);
    }
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "unknown series column '%s'; allowed: %s",
                     name ? name : "(none)", list);
}

/* Parses "MIN,MAX" (finite, MIN < MAX) into r[0], r[1]. */
static int parse_range(const char *text, double r[2]) {
    char *end, *end2;
    errno = 0;
    double a = strtod(text, &end);
    if (end == text || *end != ',')
        return 0;
    double b = strtod(end + 1, &end2);
    if (errno || end2 == end + 1 || *end2 || !isfinite(a) || !isfinite(b) || !(a < b))
        return 0;
    r[0] = a;
    r[1] = b;
    return 1;
}

/* Returns 0 on success, else the usage exit code (message printed). */
int cdem_cmd_plot_parse(int argc, char **argv, cdem_plot_args *a) {
    for (int i = 1; i < argc; i++) {
        const cdem_cli_option *o;
        const char *val;
        const cdem_cmd_arg kind = cdem_cmd_next_arg(a->help, argc, argv, &i, &o, &val);
        char msg[160];
        if (kind == CDEM_CMD_ARG_USAGE)
            return CDEM_EXIT_USAGE;
        if (kind == CDEM_CMD_ARG_POSITIONAL) {
            if (a->n_files == CDEM_PLOT_MAX_FILES)
                return cdem_cmd_usage(a->help, "too many run files (at most 64)");
            a->files[a->n_files++] = argv[i];
        } else if (cdem_cli_option_is(o, "--y")) {
            a->y = val;
        } else if (cdem_cli_option_is(o, "--x")) {
            a->x = val;
        } else if (cdem_cli_option_is(o, "--output")) {
            a->out = val;
        } else if (cdem_cli_option_is(o, "--data")) {
            a->data = val;
        } else if (cdem_cli_option_is(o, "--increment")) {
            a->increment = val;
        } else if (cdem_cli_option_is(o, "--include-poor-fits")) {
            a->include_poor = 1;
        } else if (cdem_cli_option_is(o, "--xrange") || cdem_cli_option_is(o, "--yrange")) {
            const int y = cdem_cli_option_is(o, "--yrange");
            if (!parse_range(val, a->range + 2 * y)) {
                snprintf(msg, sizeof msg, "%s '%.60s': need MIN,MAX with MIN < MAX",
                         y ? "--yrange" : "--xrange", val);
                return cdem_cmd_usage(a->help, msg);
            }
            *(y ? &a->fix_y : &a->fix_x) = 1;
        } else if (cdem_cli_option_is(o, "--window")) {
            if (!cdem_cmd_parse_number(val, &a->window) || !(a->window > 0.0)) {
                snprintf(msg, sizeof msg, "--window '%.60s': need a length in m > 0", val);
                return cdem_cmd_usage(a->help, msg);
            }
        } else { /* --width, --height */
            const int w = cdem_cli_option_is(o, "--width");
            if (!cdem_cmd_parse_int(val, 16, 20000, w ? &a->width : &a->height)) {
                snprintf(msg, sizeof msg, "%s '%.60s': need a whole number in 16..20000",
                         w ? "--width" : "--height", val);
                return cdem_cmd_usage(a->help, msg);
            }
        }
    }
    return 0;
}

cdem_status cdem_cmd_plot_read_series(const char *path, cdem_series_sample **smp, size_t *n,
                                      cdem_error *err) {
    cdem_h5_reader *r;
    CDEM_TRY(cdem_h5_reader_open(path, &r, err));
    cdem_status st = cdem_h5_reader_read_series(r, smp, n, err);
    cdem_h5_reader_close(r);
    if (st != CDEM_OK)
        cdem_error_prefix(err, "%s", path);
    return st;
}

int cdem_cmd_plot_parse_one(int argc, char **argv, cdem_plot_args *a) {
    const int rc = cdem_cmd_plot_parse(argc, argv, a);
    if (rc == 0 && a->n_files != 1)
        return cdem_cmd_usage(a->help, "need exactly one run file (RUN.h5)");
    return rc;
}

cdem_status cdem_cmd_plot_open_increment(const cdem_plot_args *a, cdem_h5_reader **r, cdem_state *s,
                                         cdem_increment_info *info, cdem_error *err) {
    cdem_h5_reader *opened = NULL;
    *r = NULL;
    CDEM_TRY(cdem_h5_reader_open(a->files[0], &opened, err));
    *r = opened;
    size_t idx;
    CDEM_TRY(cdem_h5_reader_find_increment(*r, a->increment ? a->increment : "last", &idx, err));
    return cdem_h5_reader_load_increment(*r, idx, s, info, err);
}
