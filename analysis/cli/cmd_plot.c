/* cmd_plot: see cmd_plot.h. */
#include "cmd_plot.h"

#include "mohr.h"
#include "plot.h"
#include "render.h"
#include "repose.h"
#include "voids.h"

#include "outfile.h"

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
    default:
        return s->sea_level;
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

/* ---------------------------------------------------------------- shared option parsing */
#define MAX_FILES 64

typedef struct {
    const char *cmd;              /* subcommand word, for messages */
    const char *files[MAX_FILES]; /* positional arguments */
    size_t n_files;               /* number of positional arguments */
    const char *y, *x;            /* --y, --x column names */
    const char *out;              /* -o OUT */
    const char *data;             /* --data FILE (mohr) */
    const char *increment;        /* --increment K (repose) */
    int width, height;            /* --width, --height; 0 = default */
    int fix_x, fix_y;             /* 1: --xrange / --yrange given */
    double window;                /* --window M (voids); 0 = default */
    double range[4];              /* xmin, xmax, ymin, ymax of --xrange, --yrange */
} plot_args;

static const cdem_cli_help *help_of(const char *cmd) {
    return !strcmp(cmd, "mohr")     ? &cdem_cmd_mohr_help
           : !strcmp(cmd, "repose") ? &cdem_cmd_repose_help
           : !strcmp(cmd, "voids")  ? &cdem_cmd_voids_help
                                    : &cdem_cmd_plot_series_help;
}

/* synopsis is the first usage form of the command's help (help_of) */
static int usage(const char *cmd, const char *what, const char *synopsis) {
    (void)synopsis;
    cdem_cli_usage_print(stderr, help_of(cmd), what);
    return 2;
}

static int fail(const char *cmd, const cdem_error *err) {
    const char *m = err->msg[0] ? err->msg : "unknown error";
    size_t len = strlen(cmd);
    if (!strncmp(m, cmd, len) && m[len] == ':' && m[len + 1] == ' ')
        m += len + 2; /* "mohr: ..." from the library: the command already names it */
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

static int parse_size(const char *text, int *out) {
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (errno || end == text || *end || v < 16 || v > 20000)
        return 0;
    *out = (int)v;
    return 1;
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
static int parse_args(int argc, char **argv, plot_args *a, const char *synopsis) {
    const char *cmd = a->cmd;
    static const char *const names[] = {"--y",      "--x",         "-o",      "--output",
                                        "--data",   "--increment", "--width", "--height",
                                        "--xrange", "--yrange",    "--window"};
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (!strcmp(arg, "-h") || !strcmp(arg, "--help")) {
            cdem_cli_help_print(stdout, help_of(cmd));
            return -1;
        }
        size_t f;
        const char *val = NULL;
        for (f = 0; f < sizeof names / sizeof names[0]; f++) {
            size_t len = strlen(names[f]);
            if (!strncmp(arg, names[f], len) && (arg[len] == 0 || arg[len] == '=')) {
                val = arg[len] == '=' ? arg + len + 1 : (i + 1 < argc ? argv[++i] : NULL);
                break;
            }
        }
        if (f < sizeof names / sizeof names[0]) {
            char msg[160];
            if (!val) {
                snprintf(msg, sizeof msg, "option %s needs a value", names[f]);
                return usage(cmd, msg, synopsis);
            }
            switch (f) {
            case 0:
                a->y = val;
                break;
            case 1:
                a->x = val;
                break;
            case 2:
            case 3:
                a->out = val;
                break;
            case 4:
                a->data = val;
                break;
            case 5:
                a->increment = val;
                break;
            case 8:
            case 9:
                if (!parse_range(val, a->range + 2 * (f - 8))) {
                    snprintf(msg, sizeof msg, "%s '%.60s': need MIN,MAX with MIN < MAX", names[f],
                             val);
                    return usage(cmd, msg, synopsis);
                }
                *(f == 8 ? &a->fix_x : &a->fix_y) = 1;
                break;
            case 10: {
                char *end;
                errno = 0;
                a->window = strtod(val, &end);
                if (errno || end == val || *end || !(a->window > 0.0) || !isfinite(a->window)) {
                    snprintf(msg, sizeof msg, "--window '%.60s': need a length in m > 0", val);
                    return usage(cmd, msg, synopsis);
                }
                break;
            }
            default:
                if (!parse_size(val, f == 6 ? &a->width : &a->height)) {
                    snprintf(msg, sizeof msg, "%s '%.60s': need a whole number in 16..20000",
                             names[f], val);
                    return usage(cmd, msg, synopsis);
                }
            }
            continue;
        }
        if (arg[0] == '-' && arg[1]) {
            char msg[160];
            snprintf(msg, sizeof msg, "unknown option '%.100s'", arg);
            return usage(cmd, msg, synopsis);
        }
        if (a->n_files == MAX_FILES)
            return usage(cmd, "too many run files (at most 64)", synopsis);
        a->files[a->n_files++] = arg;
    }
    return 0;
}

static const char *base_name(const char *path) {
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* Reads the whole time series of path. */
static cdem_status read_series(const char *path, cdem_series_sample **smp, size_t *n,
                               cdem_error *err) {
    cdem_h5_reader *r;
    CDEM_TRY(cdem_h5_reader_open(path, &r, err));
    cdem_status st = cdem_h5_reader_read_series(r, smp, n, err);
    cdem_h5_reader_close(r);
    if (st != CDEM_OK)
        cdem_error_prefix(err, "%s", path);
    return st;
}

/* ---------------------------------------------------------------- plot-series */
static const char series_synopsis[] =
    "RUN.h5 [RUN2.h5 ...] --y COLUMN [--x COLUMN] -o OUT.png|.pdf|.svg "
    "[--xrange MIN,MAX] [--yrange MIN,MAX] [--width N] [--height N]";
static const char *const series_forms[] = {series_synopsis, NULL};
/* the picture size options shared by the plots */
#define WIDTH_OPTION                                                                               \
    { "--width", "N", "pixels (PNG) or points (PDF, SVG), 16 to 20000" }
#define HEIGHT_OPTION                                                                              \
    { "--height", "N", "as --width" }
static const cdem_cli_option series_options[] = {
    {"--y", "COLUMN",
     "the /series column to plot: time, step, kinetic_energy, contacts, bonds, n_elements, "
     "net_displacement, boundary_force_x, boundary_force_y, base_force_x, base_force_y, "
     "axial_strain, differential_stress, sea_level"},
    {"--x", "COLUMN",
     "the x axis, any column as for --y (default time; e.g. net_displacement, or "
     "axial_strain for a biaxial stress-strain curve)"},
    {"-o, --output", "OUT.png|.pdf|.svg", "the picture"},
    {"--xrange", "MIN,MAX", "fixed x range"},
    {"--yrange", "MIN,MAX", "fixed y range"},
    WIDTH_OPTION,
    HEIGHT_OPTION,
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_plot_series_help = {
    .program = "cdem-strain plot-series",
    .forms = series_forms,
    .about = "Line plot of a time-series column of one or more runs (one curve per run), e.g. "
             "kinetic_energy to check that equilibration has settled. Columns and units: "
             "docs/format.md, \"/series\".",
    .options = series_options,
};

int cdem_cmd_plot_series(int argc, char **argv) {
    plot_args a = {.cmd = "plot-series"};
    int rc = parse_args(argc, argv, &a, series_synopsis);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (!a.n_files)
        return usage(a.cmd, "missing the run file (RUN.h5)", series_synopsis);
    if (!a.y)
        return usage(a.cmd, "missing --y COLUMN", series_synopsis);
    if (!a.out)
        return usage(a.cmd, "missing -o OUT.png|.pdf|.svg", series_synopsis);
    /* any column can be the x axis (axial_strain for a biaxial stress-strain curve) */
    const char *xname = a.x ? a.x : "time";
    cdem_error err;
    const char *ylabel = NULL, *xlabel = NULL;
    if (cdem_cmd_plot_column(NULL, 0, xname, NULL, &xlabel, &err) != CDEM_OK)
        return usage(a.cmd, err.msg, series_synopsis);
    if (cdem_cmd_plot_column(NULL, 0, a.y, NULL, &ylabel, &err) != CDEM_OK)
        return fail(a.cmd, &err);
    cdem_plot_series ser[MAX_FILES];
    double *buf[MAX_FILES] = {0};
    memset(ser, 0, sizeof ser);
    cdem_status st = CDEM_OK;
    for (size_t i = 0; i < a.n_files && st == CDEM_OK; i++) {
        cdem_series_sample *smp = NULL;
        size_t n = 0;
        st = read_series(a.files[i], &smp, &n, &err);
        if (st == CDEM_OK && n == 0)
            st = CDEM_FAIL(&err, CDEM_ERR_NOTFOUND, "%s has no time-series samples", a.files[i]);
        if (st == CDEM_OK && !(buf[i] = malloc(2 * n * sizeof(double))))
            st = CDEM_FAIL(&err, CDEM_ERR_NOMEM, "no memory for %zu samples", n);
        if (st == CDEM_OK) {
            cdem_cmd_plot_column(smp, n, xname, buf[i], NULL, &err);
            cdem_cmd_plot_column(smp, n, a.y, buf[i] + n, NULL, &err);
            ser[i] = (cdem_plot_series){.x = buf[i],
                                        .y = buf[i] + n,
                                        .n = n,
                                        .label = a.n_files > 1 ? base_name(a.files[i]) : NULL,
                                        .line = 1};
        }
        free(smp);
    }
    if (st == CDEM_OK) {
        cdem_plot p = {.title = a.n_files == 1 ? base_name(a.files[0]) : NULL,
                       .xlabel = xlabel,
                       .ylabel = ylabel,
                       .series = ser,
                       .n_series = a.n_files,
                       .fix_x = a.fix_x,
                       .xmin = a.range[0],
                       .xmax = a.range[1],
                       .fix_y = a.fix_y,
                       .ymin = a.range[2],
                       .ymax = a.range[3]};
        st = cdem_plot_to_file(a.out, &p, 1, a.width ? a.width : 1000, a.height ? a.height : 600,
                               &err);
    }
    for (size_t i = 0; i < a.n_files; i++)
        free(buf[i]);
    return st == CDEM_OK ? 0 : fail(a.cmd, &err);
}

/* ---------------------------------------------------------------- mohr */
static const char mohr_synopsis[] =
    "RUN1.h5 RUN2.h5 ... | --data FILE (columns: sigma3 q, N/m)  [-o OUT.png|.pdf|.svg] "
    "[--width N] [--height N]";

static const char *const mohr_forms[] = {mohr_synopsis, NULL};
static const cdem_cli_option mohr_options[] = {
    {"--data", "FILE", "fit peaks measured elsewhere: a text file of columns sigma3 q (N/m)"},
    {"-o, --output", "OUT.png|.pdf|.svg",
     "stress-strain curves and Mohr circles with the fitted envelope"},
    WIDTH_OPTION,
    HEIGHT_OPTION,
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_mohr_help = {
    .program = "cdem-strain mohr",
    .forms = mohr_forms,
    .about = "Mohr-Coulomb fit of biaxial tests: takes the peak differential stress of each "
             "run (sigma3 = its confining pressure) and prints the cohesion and friction "
             "angle with their standard errors (none with exactly two tests). Formulas: "
             "docs/rendering.md.",
    .options = mohr_options,
};

#define MOHR_CIRCLE_POINTS 181

/* Curves and peak values of the biaxial runs (owned arrays). */
typedef struct {
    double *sigma3, *q;        /* per test, N/m */
    double *strain[MAX_FILES]; /* axial strain per sample, per run */
    double *stress[MAX_FILES]; /* differential stress per sample (MPa), per run */
    size_t n_samples[MAX_FILES];
    size_t n; /* tests */
} mohr_data;

static void mohr_data_free(mohr_data *d) {
    free(d->sigma3);
    free(d->q);
    for (size_t i = 0; i < MAX_FILES; i++) {
        free(d->strain[i]);
        free(d->stress[i]);
    }
}

static cdem_status mohr_read_runs(const plot_args *a, mohr_data *d, cdem_error *err) {
    d->sigma3 = malloc(a->n_files * sizeof(double));
    d->q = malloc(a->n_files * sizeof(double));
    if (!d->sigma3 || !d->q)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "no memory for %zu runs", a->n_files);
    for (size_t i = 0; i < a->n_files; i++) {
        cdem_h5_reader *r;
        CDEM_TRY(cdem_h5_reader_open(a->files[i], &r, err));
        cdem_params p;
        cdem_series_sample *smp = NULL;
        size_t n = 0;
        cdem_status st = cdem_h5_reader_params(r, &p, err);
        if (st == CDEM_OK)
            st = cdem_h5_reader_read_series(r, &smp, &n, err);
        cdem_h5_reader_close(r);
        if (st == CDEM_OK && p.mode != CDEM_MODE_BIAXIAL)
            st = CDEM_FAIL(err, CDEM_ERR_INVALID,
                           "%s is a '%s' run; mohr needs biaxial test runs (boundary.mode = "
                           "biaxial)",
                           a->files[i], cdem_mode_name(p.mode));
        if (st == CDEM_OK && n == 0)
            st = CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "%s has no time-series samples", a->files[i]);
        if (st == CDEM_OK) {
            d->strain[i] = malloc(n * sizeof(double));
            d->stress[i] = malloc(n * sizeof(double));
            if (!d->strain[i] || !d->stress[i])
                st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "no memory for %zu samples", n);
        }
        if (st == CDEM_OK) {
            double peak = -INFINITY;
            for (size_t k = 0; k < n; k++) {
                d->strain[i][k] = smp[k].axial_strain;
                d->stress[i][k] = smp[k].differential_stress / 1e6;
                if (isfinite(smp[k].differential_stress))
                    peak = fmax(peak, smp[k].differential_stress);
            }
            d->n_samples[i] = n;
            d->sigma3[i] = p.confining_pressure;
            d->q[i] = peak;
        }
        free(smp);
        if (st != CDEM_OK)
            return st;
    }
    d->n = a->n_files;
    return CDEM_OK;
}

static cdem_status mohr_figure(const plot_args *a, const mohr_data *d, const cdem_mohr_fit *fit,
                               cdem_error *err) {
    size_t nt = d->n, runs = a->n_files;
    cdem_plot_series ser[MAX_FILES + 2];
    cdem_plot_series circ[MAX_FILES + 2];
    memset(ser, 0, sizeof ser);
    memset(circ, 0, sizeof circ);
    for (size_t i = 0; i < runs; i++)
        ser[i] = (cdem_plot_series){.x = d->strain[i],
                                    .y = d->stress[i],
                                    .n = d->n_samples[i],
                                    .label = base_name(a->files[i]),
                                    .line = 1};
    size_t nc = nt < MAX_FILES ? nt : MAX_FILES;
    double *pts = malloc((2 * nc * MOHR_CIRCLE_POINTS + 4) * sizeof(double));
    if (!pts)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "no memory for the Mohr circles");
    double smax = 0;
    for (size_t i = 0; i < nc; i++) {
        double c = (d->sigma3[i] + 0.5 * d->q[i]) / 1e6, r = 0.5 * d->q[i] / 1e6;
        double *x = pts + 2 * i * MOHR_CIRCLE_POINTS, *y = x + MOHR_CIRCLE_POINTS;
        for (int k = 0; k < MOHR_CIRCLE_POINTS; k++) {
            double t = M_PI * k / (MOHR_CIRCLE_POINTS - 1);
            x[k] = c + r * cos(t);
            y[k] = r * sin(t);
        }
        smax = fmax(smax, c + r);
        circ[i] = (cdem_plot_series){
            .x = x, .y = y, .n = MOHR_CIRCLE_POINTS, .line = 1, .colour = cdem_plot_palette(i)};
    }
    double *ex = pts + 2 * nc * MOHR_CIRCLE_POINTS, *ey = ex + 2;
    ex[0] = 0;
    ex[1] = smax * 1.05;
    ey[0] = fit->cohesion / 1e6;
    ey[1] = ey[0] + ex[1] * tan(fit->friction);
    char elabel[128];
    snprintf(elabel, sizeof elabel, "C = %.3g MPa, phi = %.1f deg", fit->cohesion / 1e6,
             fit->friction * 180 / M_PI);
    circ[nc] = (cdem_plot_series){
        .x = ex, .y = ey, .n = 2, .line = 1, .dashed = 1, .label = elabel, .colour = {0, 0, 0, 1}};
    cdem_plot panels[2] = {
        {.title = "Biaxial tests",
         .xlabel = "Axial strain",
         .ylabel = "Differential stress (MPa)",
         .series = ser,
         .n_series = runs},
        {.title = "Mohr circles at peak stress",
         .xlabel = "Normal stress (MPa)",
         .ylabel = "Shear stress (MPa)",
         .series = circ,
         .n_series = nc + 1,
         .equal_aspect = 1,
         .fix_x = 1,
         .xmin = 0,
         .xmax = smax * 1.05,
         .fix_y = 1,
         .ymin = 0,
         .ymax = fmax(ey[1], 0.6 * smax)},
    };
    size_t np = runs ? 2 : 1;
    cdem_status st =
        cdem_plot_to_file(a->out, runs ? panels : panels + 1, np,
                          a->width ? a->width : (int)(700 * np), a->height ? a->height : 560, err);
    free(pts);
    return st;
}

int cdem_cmd_plot_mohr(int argc, char **argv) {
    plot_args a = {.cmd = "mohr"};
    int rc = parse_args(argc, argv, &a, mohr_synopsis);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (a.data && a.n_files)
        return usage(a.cmd, "give either run files or --data FILE, not both", mohr_synopsis);
    if (!a.data && a.n_files < 2)
        return usage(a.cmd, "need at least 2 biaxial runs (or --data FILE)", mohr_synopsis);
    cdem_error err;
    mohr_data d;
    memset(&d, 0, sizeof d);
    cdem_status st = a.data ? cdem_mohr_read_table(a.data, &d.sigma3, &d.q, &d.n, &err)
                            : mohr_read_runs(&a, &d, &err);
    cdem_mohr_fit fit;
    if (st == CDEM_OK)
        st = cdem_mohr_fit_envelope(d.sigma3, d.q, d.n, &fit, &err);
    if (st == CDEM_OK) {
        for (size_t i = 0; i < d.n; i++)
            printf("test %zu: sigma3 = %.6g MPa, peak q = %.6g MPa, sigma1 = %.6g MPa\n", i + 1,
                   d.sigma3[i] / 1e6, d.q[i] / 1e6, (d.sigma3[i] + d.q[i]) / 1e6);
        if (isfinite(fit.cohesion_err))
            printf("cohesion = %.4g +- %.2g MPa, friction angle = %.2f +- %.2f deg\n",
                   fit.cohesion / 1e6, fit.cohesion_err / 1e6, fit.friction * 180 / M_PI,
                   fit.friction_err * 180 / M_PI);
        else
            printf("cohesion = %.4g +- n/a MPa, friction angle = %.2f +- n/a deg (2 tests: "
                   "exact fit, no uncertainty)\n",
                   fit.cohesion / 1e6, fit.friction * 180 / M_PI);
    }
    if (st == CDEM_OK && a.out)
        st = mohr_figure(&a, &d, &fit, &err);
    mohr_data_free(&d);
    return st == CDEM_OK ? 0 : fail(a.cmd, &err);
}

/* Loads the increment `which` (K, last, equil, first; NULL = last) of an open run into s. */
static cdem_status load_increment(cdem_h5_reader *r, const char *which, cdem_state *s,
                                  cdem_increment_info *info, cdem_error *err) {
    size_t idx;
    CDEM_TRY(cdem_h5_reader_find_increment(r, which ? which : "last", &idx, err));
    return cdem_h5_reader_load_increment(r, idx, s, info, err);
}

/* ---------------------------------------------------------------- repose */
static const char repose_synopsis[] =
    "RUN.h5 [--increment K|last|equil|first] [-o OUT.png|.pdf|.svg] [--width N] [--height N]";
static const char *const repose_forms[] = {repose_synopsis, NULL};
static const cdem_cli_option repose_options[] = {
    {"--increment", "K|last|equil|first", "the increment (default last)"},
    {"-o, --output", "OUT.png|.pdf|.svg", "the free surface with the fitted flanks"},
    WIDTH_OPTION,
    HEIGHT_OPTION,
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_repose_help = {
    .program = "cdem-strain repose",
    .forms = repose_forms,
    .about = "Angle of repose: the slope of the free surface of a repose-collapse run, fitted "
             "on each flank (docs/analysis.md).",
    .options = repose_options,
};

static cdem_status repose_figure(const plot_args *a, const cdem_state *s, int number,
                                 const cdem_repose_result *res, cdem_error *err) {
    cdem_render_format fmt;
    CDEM_TRY(cdem_render_format_from_path(a->out, &fmt, err));
    cdem_render_options o;
    cdem_render_options_default(&o);
    o.width = a->width ? a->width : 1200;
    o.height = a->height;
    char label[160];
    snprintf(label, sizeof label, "Increment %d   Angle of repose %.1f deg", number,
             res->angle_deg);
    cdem_render_scene sc = {.state = s, .label = label};
    int h = o.height;
    if (!h)
        CDEM_TRY(cdem_render_auto_height(&sc, &o, &h, err));
    cdem_render_layout lay;
    CDEM_TRY(cdem_render_layout_compute(&sc, &o, o.width, h, &lay, err));
    cdem_render_target t;
    CDEM_TRY(cdem_render_target_open(&t, a->out, fmt, o.width, h, a->cmd, err));
    cairo_t *cr = cairo_create(t.surf);
    cdem_status st = cdem_render_draw(cr, o.width, h, &sc, &o, err);
    for (int side = 0; side < 2 && st == CDEM_OK; side++) {
        /* each fitted flank's line, extended by one column at both ends */
        const cdem_repose_flank *f = &res->flank[side];
        if (f->n < 2)
            continue;
        double x0 = f->x_first - res->column_width, x1 = f->x_last + res->column_width;
        double d0x, d0y, d1x, d1y;
        cdem_render_layout_to_device(&lay, x0, f->intercept + f->slope * x0, &d0x, &d0y);
        cdem_render_layout_to_device(&lay, x1, f->intercept + f->slope * x1, &d1x, &d1y);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_line_width(cr, fmax(2.0, o.width / 400.0));
        cairo_move_to(cr, d0x, d0y);
        cairo_line_to(cr, d1x, d1y);
        cairo_stroke(cr);
    }
    cairo_destroy(cr);
    return cdem_render_target_close(&t, st, err);
}

int cdem_cmd_plot_repose(int argc, char **argv) {
    plot_args a = {.cmd = "repose"};
    int rc = parse_args(argc, argv, &a, repose_synopsis);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (a.n_files != 1)
        return usage(a.cmd, "need exactly one run file (RUN.h5)", repose_synopsis);
    cdem_error err;
    cdem_render_format fmt;
    if (a.out && cdem_render_format_from_path(a.out, &fmt, &err) != CDEM_OK)
        return fail(a.cmd, &err);
    cdem_h5_reader *r;
    cdem_state s = {0};
    cdem_increment_info info;
    cdem_repose_result res;
    if (cdem_h5_reader_open(a.files[0], &r, &err) != CDEM_OK)
        return fail(a.cmd, &err);
    cdem_status st = load_increment(r, a.increment, &s, &info, &err);
    cdem_params prm;
    if (st == CDEM_OK && cdem_h5_reader_params(r, &prm, &err) == CDEM_OK &&
        prm.mode != CDEM_MODE_REPOSE)
        fprintf(stderr, "cdem-strain repose: note: %s is a '%s' run, not a repose-collapse run\n",
                a.files[0], cdem_mode_name(prm.mode));
    if (st == CDEM_OK)
        st = cdem_repose_measure(&s, &res, &err);
    if (st == CDEM_OK) {
        printf("angle of repose = %.2f deg (increment %d, %zu surface elements fitted, columns "
               "%.4g m wide)\n",
               res.angle_deg, (int)info.number, res.n_fitted, res.column_width);
        for (int side = 0; side < 2; side++)
            if (res.flank[side].n >= 2)
                printf("  %s flank: %.2f deg, %zu elements, x %.4g .. %.4g m, rms misfit %.4g m\n",
                       side ? "right" : "left", res.flank[side].angle_deg, res.flank[side].n,
                       res.flank[side].x_first, res.flank[side].x_last,
                       res.flank[side].residual_rms);
    }
    if (st == CDEM_OK && a.out)
        st = repose_figure(&a, &s, (int)info.number, &res, &err);
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
    return st == CDEM_OK ? 0 : fail_on(a.cmd, a.files[0], &err);
}

/* ---------------------------------------------------------------- voids */
static const char voids_synopsis[] = "RUN.h5 [--increment K|last|equil|first] [--window M]";
static const char *const voids_forms[] = {voids_synopsis, NULL};
static const cdem_cli_option voids_options[] = {
    {"--increment", "K|last|equil|first", "the increment (default last)"},
    {"--window", "M", "horizontal span of the steepest-slope measure in m (default 1000)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_voids_help = {
    .program = "cdem-strain voids",
    .forms = voids_forms,
    .about = "Open space a rock mass should not hold, in one increment: the steepest surface "
             "slope over a horizontal window (cliffs, chasm walls), voids (closed-off room for "
             "the largest element: cavities under arches, gaps behind rigid blocks) and the "
             "deepest open fissure (analysis/measure/voids.h, docs/analysis.md).",
    .options = voids_options,
};

int cdem_cmd_plot_voids(int argc, char **argv) {
    plot_args a = {.cmd = "voids"};
    int rc = parse_args(argc, argv, &a, voids_synopsis);
    if (rc)
        return rc < 0 ? 0 : rc;
    if (a.n_files != 1)
        return usage(a.cmd, "need exactly one run file (RUN.h5)", voids_synopsis);
    if (a.out)
        return usage(a.cmd, "prints numbers only (no -o)", voids_synopsis);
    cdem_error err;
    cdem_h5_reader *r;
    cdem_state s = {0};
    cdem_increment_info info;
    cdem_voids_result res;
    if (cdem_h5_reader_open(a.files[0], &r, &err) != CDEM_OK)
        return fail(a.cmd, &err);
    cdem_status st = load_increment(r, a.increment, &s, &info, &err);
    if (st == CDEM_OK)
        st = cdem_voids_measure(&s, a.window > 0.0 ? a.window : 1000.0, &res, &err);
    if (st == CDEM_OK) {
        printf("increment %d\n", (int)info.number);
        printf("steepest surface slope = %.2f deg over %.4g m (columns at x = %.6g and %.6g m)\n",
               res.steepest_deg, res.window, res.steepest_x0, res.steepest_x1);
        printf("voids = %zu (closed-off room for the largest element, radius %.4g m), their room "
               "%.4g m^2\n",
               res.n_voids, res.min_clearance, res.void_area);
        printf("largest clearance inside = %.4g m (%.2f x the largest radius) at x = %.6g m, y = "
               "%.6g m\n",
               res.largest_clearance, res.largest_clearance / res.min_clearance, res.largest_x,
               res.largest_y);
        printf("deepest open fissure = %.4g m (below the rims within %.4g m on either side) at x "
               "= %.6g m, bottom y = %.6g m\n",
               res.fissure_depth, res.fissure_width, res.fissure_x, res.fissure_y);
    }
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
    return st == CDEM_OK ? 0 : fail(a.cmd, &err);
}
