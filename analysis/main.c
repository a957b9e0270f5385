/* cdem-strain: the command line of the analysis tool.
 *
 * Subcommands are rows of one static const table {name, function, one-line help}; a first
 * argument that is an existing file (not a subcommand) means "compute". This is the only
 * place that prints and chooses exit codes: 0 success, 1 error ("cdem-strain: <message>" on
 * stderr), 2 usage error. Results go to stdout (or -o FILE) so they can be redirected. */
#include "analysis.h"
#include "cmd_render.h"
#include "cmd_plot.h"
#include "cmd_wedge.h"
#include "biaxial.h"
#include "cdem2d.h"
#include "outfile.h"
#include "qexport.h"
#include "quantity.h"
#include "sspx.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef CDEM_VERSION
#define CDEM_VERSION "0.0.0"
#endif

enum { EXIT_OK = 0, EXIT_ERROR = 1, EXIT_USAGE = 2 };

/* Parsed options shared by the subcommands (each uses the ones it documents). */
typedef struct {
    const char *file;       /* positional: the run file (or cdem2D folder for import) */
    const char *dir;        /* second positional: output directory (export-sspx) */
    const char *increment;  /* --increment K|last|equil|first|all */
    const char *increments; /* --increments A-B */
    const char *quantity;   /* --quantity NAME */
    const char *format;     /* --format csv|h5 */
    const char *out;        /* -o OUT */
    const char *prefix;     /* --prefix P */
    const char *element;    /* --element ID */
} options;

typedef int (*command_fn)(const options *o);

typedef struct {
    const char *name;  /* subcommand word */
    command_fn run;    /* implementation */
    const char *usage; /* argument synopsis */
    const char *help;  /* one line */
} command;

static void print_error(const cdem_error *err) {
    const char *s = err->msg[0] ? err->msg : "unknown error";
    while (*s) {
        const char *nl = strchr(s, '\n');
        int len = nl ? (int)(nl - s) : (int)strlen(s);
        fprintf(stderr, "cdem-strain: %.*s\n", len, s);
        s += len + (nl ? 1 : 0);
    }
}

static int fail_with(const cdem_error *err) {
    print_error(err);
    return EXIT_ERROR;
}

static int usage_error(const char *what) {
    fprintf(stderr, "cdem-strain: %s\nTry 'cdem-strain --help' for more information.\n", what);
    return EXIT_USAGE;
}

static int open_run(const options *o, cdem_analysis **a) {
    cdem_error err;
    if (!o->file)
        return usage_error("missing the run file (RUN.h5)");
    if (cdem_analysis_open(o->file, a, &err) != CDEM_OK)
        return fail_with(&err);
    return EXIT_OK;
}

static const char *phase_name(int phase) {
    return phase == CDEM_PHASE_EQUILIBRATION ? "equilibration"
           : phase == CDEM_PHASE_DEFORMATION ? "deformation"
           : phase == CDEM_PHASE_SETTLING    ? "settling"
                                             : "unknown";
}

/* ---------------------------------------------------------------- info */
/* info on a file without increments yet (a run that has just started, or was killed
 * before its first increment): the stored texts and "increments: 0". -1 when it has some. */
static int info_without_increments(const char *path) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        return -1; /* open_run reports the problem */
    if (cdem_h5_reader_increment_count(r) > 0) {
        cdem_h5_reader_close(r);
        return -1;
    }
    const char *sum = cdem_h5_reader_summary(r);
    printf("%s%s", sum, sum[0] && sum[strlen(sum) - 1] != '\n' ? "\n" : "");
    const char *reason = cdem_h5_reader_stop_reason(r), *detail = cdem_h5_reader_stop_detail(r);
    printf("\nstop reason: %s%s%s\n", reason[0] ? reason : "(none recorded)", detail[0] ? ": " : "",
           detail);
    printf("increments: 0 (none written yet)\n");
    cdem_h5_reader_close(r);
    return EXIT_OK;
}

static int cmd_info(const options *o) {
    int none = o->file ? info_without_increments(o->file) : -1;
    if (none >= 0)
        return none;
    cdem_analysis *a;
    int rc = open_run(o, &a);
    if (rc)
        return rc;
    cdem_h5_reader *r = cdem_analysis_reader(a);
    printf("%s", cdem_h5_reader_summary(r));
    if (cdem_h5_reader_summary(r)[0] &&
        cdem_h5_reader_summary(r)[strlen(cdem_h5_reader_summary(r)) - 1] != '\n')
        printf("\n");
    const char *reason = cdem_h5_reader_stop_reason(r), *detail = cdem_h5_reader_stop_detail(r);
    printf("\nstop reason: %s%s%s\n", reason[0] ? reason : "(none recorded)", detail[0] ? ": " : "",
           detail);
    printf("increments: %zu (end of equilibration: increment %d)\n", cdem_analysis_count(a),
           (int)cdem_analysis_info(a, cdem_analysis_equil_index(a))->number);
    printf("%9s %12s %12s %-13s %14s %9s\n", "increment", "step", "time_s", "phase", "net_displ_m",
           "elements");
    for (size_t k = 0; k < cdem_analysis_count(a); k++) {
        const cdem_increment_info *in = cdem_analysis_info(a, k);
        printf("%9d %12lld %12.3f %-13s %14.3f %9lld\n", (int)in->number, (long long)in->step,
               in->time, phase_name(in->phase), in->net_displacement, (long long)in->n_elements);
    }
    cdem_analysis_close(a);
    return EXIT_OK;
}

/* ---------------------------------------------------------------- compute */
static int cmd_compute(const options *o) {
    if (!o->increment)
        return usage_error("compute needs --increment K|last|equil|first|all");
    if (!o->quantity)
        return usage_error("compute needs --quantity NAME (see 'cdem-strain quantities')");
    const char *format = o->format ? o->format : "csv";
    if (strcmp(format, "csv") != 0 && strcmp(format, "h5") != 0)
        return usage_error("--format must be csv or h5");
    if (strcmp(format, "h5") == 0 && !o->out)
        return usage_error("--format h5 needs -o OUT.h5");
    cdem_error err;
    const cdem_quantity *q;
    if (cdem_quantity_find(o->quantity, &q, &err) != CDEM_OK)
        return fail_with(&err);
    cdem_analysis *a;
    int rc = open_run(o, &a);
    if (rc)
        return rc;
    size_t first, last;
    int all = strcmp(o->increment, "all") == 0;
    if (all) {
        first = 0;
        last = cdem_analysis_count(a) - 1;
    } else if (cdem_analysis_find(a, o->increment, &first, &err) != CDEM_OK) {
        cdem_analysis_close(a);
        return fail_with(&err);
    } else {
        last = first;
    }
    FILE *f = stdout;
    cdem_qexport_h5 *h = NULL;
    cdem_status st = CDEM_OK;
    cdem_outfile of = {.active = 0}; /* -o OUT is written to OUT.tmp, renamed on success */
    if (o->out)
        st = cdem_outfile_begin(&of, o->out, &err);
    if (st == CDEM_OK && strcmp(format, "h5") == 0) {
        st = cdem_qexport_h5_create(of.tmp, q, &h, &err);
    } else if (st == CDEM_OK && o->out) {
        f = fopen(of.tmp, "w");
        if (!f)
            st = CDEM_FAIL(&err, CDEM_ERR_IO, "cannot create %s: %s", of.tmp, strerror(errno));
    }
    if (st == CDEM_OK && !h)
        st = cdem_qexport_csv_header(f, all, &err);
    for (size_t k = first; k <= last && st == CDEM_OK; k++) {
        const cdem_increment_info *in = cdem_analysis_info(a, k);
        if (q->needs_stress && !in->has_stress && all)
            continue; /* "all" skips increments without stress */
        const cdem_state *s;
        double *v;
        st = cdem_analysis_values(a, k, q, &s, &v, &err);
        if (st != CDEM_OK)
            break;
        st = h ? cdem_qexport_h5_write(h, in->number, s, v, &err)
               : cdem_qexport_csv_rows(f, all, in->number, s, v, &err);
        free(v);
    }
    if (h) {
        cdem_error e2;
        cdem_status st2 = cdem_qexport_h5_close(h, &e2);
        if (st == CDEM_OK && st2 != CDEM_OK) {
            err = e2;
            st = st2;
        }
    }
    if (f && f != stdout && fclose(f) != 0 && st == CDEM_OK)
        st = CDEM_FAIL(&err, CDEM_ERR_IO, "error writing %s", of.tmp);
    if (of.active)
        st = cdem_outfile_end(&of, st, &err);
    cdem_analysis_close(a);
    return st == CDEM_OK ? EXIT_OK : fail_with(&err);
}

/* ---------------------------------------------------------------- element */
static int cmd_element(const options *o) {
    if (!o->increment || !o->element)
        return usage_error("element needs --increment K and --element ID");
    char *end;
    long id = strtol(o->element, &end, 10);
    if (*end || end == o->element)
        return usage_error("--element must be an element id (a whole number)");
    cdem_analysis *a;
    int rc = open_run(o, &a);
    if (rc)
        return rc;
    cdem_error err;
    size_t k;
    const cdem_state *s;
    if (cdem_analysis_find(a, o->increment, &k, &err) != CDEM_OK ||
        cdem_analysis_state(a, k, &s, &err) != CDEM_OK) {
        cdem_analysis_close(a);
        return fail_with(&err);
    }
    size_t idx = SIZE_MAX;
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == id)
            idx = i;
    const cdem_increment_info *in = cdem_analysis_info(a, k);
    if (idx == SIZE_MAX) {
        CDEM_FAIL(&err, CDEM_ERR_NOTFOUND, "element %ld is not in increment %d (%zu elements)", id,
                  (int)in->number, s->n);
        cdem_analysis_close(a);
        return fail_with(&err);
    }
    printf("element %ld at increment %d\n", id, (int)in->number);
    printf("  %-18s %.3f m\n  %-18s %.3f m\n  %-18s %.3f m\n  %-18s %d\n  %-18s %d\n", "x",
           s->x[idx], "y", s->y[idx], "radius", s->radius[idx], "layer", (int)s->layer[idx],
           "born (increment)", (int)s->born[idx]);
    printf("  %-18s%s%s%s\n", "kind", (s->flags[idx] & CDEM_FLAGS_BOUNDARY) ? " wall" : " free",
           (s->flags[idx] & CDEM_FLAG_GROWTH) ? " growth" : "",
           (s->flags[idx] & CDEM_FLAG_WEAK) ? " weak" : "");
    size_t nq;
    const cdem_quantity *t = cdem_quantity_table(&nq);
    const int has_stress = in->has_stress;
    for (size_t j = 0; j < nq; j++) {
        if (t[j].needs_stress && !has_stress)
            continue;
        double *v;
        if (cdem_analysis_values(a, k, &t[j], &s, &v, &err) != CDEM_OK) {
            cdem_analysis_close(a);
            return fail_with(&err);
        }
        /* the state pointer was refreshed: find the element again */
        for (size_t i = 0; i < s->n; i++)
            if (s->id[i] == id)
                idx = i;
        if (isfinite(v[idx]))
            printf("  %-18s %.6g %s\n", t[j].name, v[idx], t[j].unit);
        else
            printf("  %-18s undefined\n", t[j].name);
        free(v);
    }
    cdem_analysis_close(a);
    return EXIT_OK;
}

/* ---------------------------------------------------------------- limits */
static int cmd_limits(const options *o) {
    if (!o->increment || !o->quantity)
        return usage_error("limits needs --increment K and --quantity NAME");
    cdem_error err;
    const cdem_quantity *q;
    if (cdem_quantity_find(o->quantity, &q, &err) != CDEM_OK)
        return fail_with(&err);
    cdem_analysis *a;
    int rc = open_run(o, &a);
    if (rc)
        return rc;
    size_t k;
    cdem_limits l;
    if (cdem_analysis_find(a, o->increment, &k, &err) != CDEM_OK ||
        cdem_analysis_limits(a, k, q, &l, &err) != CDEM_OK) {
        cdem_analysis_close(a);
        return fail_with(&err);
    }
    printf("quantity %s (%s)\n", q->name, q->label);
    printf("scale %s\n", q->scale == CDEM_SCALE_SIGNED ? "signed (blue-white-red)"
                                                       : "magnitude (blue-green-red)");
    printf("vmin %.9g %s\nvmax %.9g %s\nthreshold %.9g %s\n", l.vmin, q->unit, l.vmax, q->unit,
           l.threshold, q->unit);
    cdem_analysis_close(a);
    return EXIT_OK;
}

/* ---------------------------------------------------------------- exports */
static int cmd_export_sspx(const options *o) {
    if (!o->increments)
        return usage_error("export-sspx needs --increments A-B (e.g. 56-282, equil-last)");
    if (!o->dir)
        return usage_error("export-sspx needs an output directory");
    struct stat sb;
    if (stat(o->dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) {
        cdem_error err;
        CDEM_FAIL(&err, CDEM_ERR_IO, "output directory %s does not exist", o->dir);
        return fail_with(&err);
    }
    cdem_analysis *a;
    int rc = open_run(o, &a);
    if (rc)
        return rc;
    cdem_error err;
    size_t first, last, written;
    const char *prefix = o->prefix ? o->prefix : cdem_analysis_params(a)->prefix;
    if (!prefix[0])
        prefix = "cdem";
    cdem_status st = cdem_sspx_parse_range(a, o->increments, &first, &last, &err);
    if (st == CDEM_OK)
        st = cdem_sspx_export(a, first, last, o->dir, prefix, &written, &err);
    if (st == CDEM_OK)
        fprintf(stderr, "cdem-strain: wrote %zu files %s/%s%d.txt .. %s%d.txt\n", written, o->dir,
                prefix, (int)cdem_analysis_info(a, first)->number, prefix,
                (int)cdem_analysis_info(a, last)->number);
    cdem_analysis_close(a);
    return st == CDEM_OK ? EXIT_OK : fail_with(&err);
}

static int cmd_export_biaxial(const options *o) {
    if (!o->out)
        return usage_error("export-biaxial needs -o OUT.txt");
    cdem_analysis *a;
    int rc = open_run(o, &a);
    if (rc)
        return rc;
    cdem_error err;
    cdem_series_sample *smp = NULL;
    size_t n = 0;
    cdem_status st = CDEM_OK;
    if (cdem_analysis_params(a)->mode != CDEM_MODE_BIAXIAL)
        st = CDEM_FAIL(&err, CDEM_ERR_INVALID,
                       "%s is a '%s' run; export-biaxial needs a biaxial test run", o->file,
                       cdem_mode_name(cdem_analysis_params(a)->mode));
    if (st == CDEM_OK)
        st = cdem_h5_reader_read_series(cdem_analysis_reader(a), &smp, &n, &err);
    if (st == CDEM_OK)
        st = cdem_biaxial_write(o->out, smp, n, &err);
    free(smp);
    cdem_analysis_close(a);
    return st == CDEM_OK ? EXIT_OK : fail_with(&err);
}

static int cmd_import_cdem2d(const options *o) {
    if (!o->file)
        return usage_error("import-cdem2d needs the cdem2D folder");
    if (!o->out)
        return usage_error("import-cdem2d needs -o OUT.h5");
    cdem_error err;
    if (cdem_cdem2d_import_h5(o->file, o->out, &err) != CDEM_OK)
        return fail_with(&err);
    return EXIT_OK;
}

static int cmd_quantities(const options *o) {
    (void)o;
    size_t n;
    const cdem_quantity *t = cdem_quantity_table(&n);
    for (size_t i = 0; i < n; i++)
        printf("%-18s %-5s %-9s %s%s\n", t[i].name, t[i].unit[0] ? t[i].unit : "-",
               t[i].scale == CDEM_SCALE_SIGNED ? "signed" : "magnitude", t[i].label,
               t[i].needs_stress ? " (needs stress)" : "");
    return EXIT_OK;
}

static const command commands[] = {
    {"info", cmd_info, "RUN.h5", "summary, stop reason and the list of increments"},
    {"compute", cmd_compute,
     "RUN.h5 --increment K|last|equil|all --quantity NAME [--format csv|h5] [-o OUT]",
     "per-element values of a quantity (CSV id,x,y,value, or HDF5)"},
    {"element", cmd_element, "RUN.h5 --increment K --element ID",
     "coordinates and every applicable value of one element"},
    {"limits", cmd_limits, "RUN.h5 --increment K --quantity NAME",
     "colour-bar limits of a quantity at an increment"},
    {"export-sspx", cmd_export_sspx, "RUN.h5 --increments A-B [--prefix P] DIR",
     "one SSPX text file per increment (DIR/<prefix><number>.txt)"},
    {"export-biaxial", cmd_export_biaxial, "RUN.h5 -o OUT.txt",
     "biaxial test series: time step, axial strain, differential stress"},
    {"import-cdem2d", cmd_import_cdem2d, "DIR -o OUT.h5",
     "convert a cdem2D simulation folder into a cdem file"},
    {"quantities", cmd_quantities, "", "list every quantity name with unit and colour scale"},
    /* "render" has many options of its own: it is dispatched to cmd_render.c before this
     * table is searched (see main). */
};

static void print_help(void) {
    printf("usage: cdem-strain COMMAND [ARGS]\n       cdem-strain RUN.h5 --increment K "
           "--quantity NAME ...   (same as compute)\n\nCommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        printf("  %-15s %s\n  %-15s   %s\n", commands[i].name, commands[i].help, "",
               commands[i].usage);
    printf("  %-15s %s\n  %-15s   %s\n", "render",
           "pictures of increments (PNG, PDF, SVG) and animated GIFs", "",
           "RUN.h5 [--increment K|last|equil|all] [--color QUANTITY] -o OUT.png|DIR [--gif OUT.gif]"
           " (cdem-strain render --help for all options)");
    printf("  %-15s %s\n  %-15s   %s\n", "plot-series", "line plot of time-series columns", "",
           "RUN.h5 [RUN2.h5 ...] --y COLUMN [--x time|step|net_displacement] -o OUT.png");
    printf("  %-15s %s\n  %-15s   %s\n", "mohr", "Mohr-Coulomb fit of biaxial tests", "",
           "RUN1.h5 RUN2.h5 ... | --data FILE  [-o OUT.png]");
    printf("  %-15s %s\n  %-15s   %s\n", "repose", "angle of repose of the free surface", "",
           "RUN.h5 [--increment K] [-o OUT.png]");
    printf("  %-15s %s\n  %-15s   %s\n", "voids",
           "steepest surface slope and open voids (cliffs, chasms, cavities)", "",
           "RUN.h5 [--increment K] [--window M]");
    printf("  %-15s %s\n  %-15s   %s\n", "wedge",
           "accretionary-wedge height, length, taper, area, forces", "",
           "RUN.h5 [-o OUT.csv] [--increment K|last|all] [--threshold M]");
    printf("  %-15s %s\n  %-15s   %s\n", "plot-csv",
           "curves of CSV columns, several files per panel", "",
           "A.csv [B.csv ...] --x COL --y COL[,COL...] -o OUT.png [--columns N]");
    printf("\nQuantities, formulas and rules: docs/analysis.md; text formats: "
           "docs/formats-text.md.\nExit status: 0 success, 1 error, 2 usage error.\n");
}

static int parse_options(int argc, char **argv, int start, options *o) {
    memset(o, 0, sizeof *o);
    static const struct {
        const char *flag;
        size_t offset;
    } flags[] = {{"--increment", offsetof(options, increment)},
                 {"--increments", offsetof(options, increments)},
                 {"--quantity", offsetof(options, quantity)},
                 {"--format", offsetof(options, format)},
                 {"-o", offsetof(options, out)},
                 {"--output", offsetof(options, out)},
                 {"--prefix", offsetof(options, prefix)},
                 {"--element", offsetof(options, element)}};
    for (int i = start; i < argc; i++) {
        const char *arg = argv[i];
        int matched = 0;
        for (size_t f = 0; f < sizeof flags / sizeof flags[0]; f++) {
            size_t len = strlen(flags[f].flag);
            if (strncmp(arg, flags[f].flag, len) != 0 || (arg[len] && arg[len] != '='))
                continue;
            const char *val = arg[len] == '=' ? arg + len + 1 : (i + 1 < argc ? argv[++i] : NULL);
            if (!val) {
                char msg[128];
                snprintf(msg, sizeof msg, "option %s needs a value", flags[f].flag);
                return usage_error(msg);
            }
            *(const char **)((char *)o + flags[f].offset) = val;
            matched = 1;
            break;
        }
        if (matched)
            continue;
        if (arg[0] == '-' && arg[1]) {
            char msg[160];
            snprintf(msg, sizeof msg, "unknown option '%.100s'", arg);
            return usage_error(msg);
        }
        if (!o->file)
            o->file = arg;
        else if (!o->dir)
            o->dir = arg;
        else {
            char msg[160];
            snprintf(msg, sizeof msg, "unexpected argument '%.100s'", arg);
            return usage_error(msg);
        }
    }
    return EXIT_OK;
}

int main(int argc, char **argv) {
    if (argc < 2)
        return usage_error("missing command");
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "help")) {
        print_help();
        return EXIT_OK;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("cdem-strain %s\n", CDEM_VERSION);
        return EXIT_OK;
    }
    if (!strcmp(argv[1], "render"))
        return cdem_cmd_render(argc - 1, argv + 1);
    if (!strcmp(argv[1], "plot-series"))
        return cdem_cmd_plot_series(argc - 1, argv + 1);
    if (!strcmp(argv[1], "mohr"))
        return cdem_cmd_plot_mohr(argc - 1, argv + 1);
    if (!strcmp(argv[1], "repose"))
        return cdem_cmd_plot_repose(argc - 1, argv + 1);
    if (!strcmp(argv[1], "voids"))
        return cdem_cmd_plot_voids(argc - 1, argv + 1);
    if (!strcmp(argv[1], "wedge"))
        return cdem_cmd_wedge(argc - 1, argv + 1);
    if (!strcmp(argv[1], "plot-csv"))
        return cdem_cmd_plot_csv(argc - 1, argv + 1);
    options o;
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (!strcmp(argv[1], commands[i].name)) {
            int rc = parse_options(argc, argv, 2, &o);
            return rc ? rc : commands[i].run(&o);
        }
    struct stat sb;
    if (argv[1][0] != '-' && stat(argv[1], &sb) == 0 && S_ISREG(sb.st_mode)) {
        int rc = parse_options(argc, argv, 1, &o);
        return rc ? rc : cmd_compute(&o);
    }
    char msg[200];
    snprintf(msg, sizeof msg, "unknown command '%.100s' (and not an existing file)", argv[1]);
    return usage_error(msg);
}
