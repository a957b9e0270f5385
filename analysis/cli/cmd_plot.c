/* cmd_plot: see cmd_plot.h. */
#include "cmd_plot.h"

#include "cmd_support.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *name;  /* column name */
    const char *label; /* axis label with unit */
} column_def;

static const column_def columns[] = {
    {"time", "Time (s)"},
    {"step", "Time step"},
    {"kinetic_energy", "Kinetic energy (J/m)"},
    {"contacts", "Contacts"},
    {"bonds", "Bonds"},
    {"n_elements", "Elements"},
    {"net_displacement", "Net displacement (m)"},
    {"boundary_force_x", "Boundary force x (N)"},
    {"boundary_force_y", "Boundary force y (N)"},
    {"base_force_x", "Base force x (N)"},
    {"base_force_y", "Base force y (N)"},
    {"axial_strain", "Axial strain"},
    {"differential_stress", "Differential stress (N/m)"},
    {"sea_level", "Sea level (m)"},
    {"left_wall_force_x", "Left wall force x (N)"},
    {"left_wall_force_y", "Left wall force y (N)"},
    {"right_wall_force_x", "Right wall force x (N)"},
    {"right_wall_force_y", "Right wall force y (N)"},
};
#define N_COLUMNS (sizeof columns / sizeof columns[0])

static double column_value(const cdem_series_sample *s, size_t c) {
    switch (c) {
    case 0:
        return s->time;
    case 1:
        return (double)s->step;
    case 2:
        return s->kinetic_energy;
    case 3:
        return (double)s->contacts;
    case 4:
        return (double)s->bonds;
    case 5:
        return (double)s->n_elements;
    case 6:
        return s->net_displacement;
    case 7:
        return s->boundary_force_x;
    case 8:
        return s->boundary_force_y;
    case 9:
        return s->base_force_x;
    case 10:
        return s->base_force_y;
    case 11:
        return s->axial_strain;
    case 12:
        return s->differential_stress;
    case 13:
        return s->sea_level;
    case 14:
        return s->left_wall_force_x;
    case 15:
        return s->left_wall_force_y;
    case 16:
        return s->right_wall_force_x;
    default:
        return s->right_wall_force_y;
    }
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
