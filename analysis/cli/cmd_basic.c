/* cmd_basic: the simple subcommands of cdem-strain (info, compute, element, limits,
 * export-sspx, export-biaxial, import-cdem2d, quantities). They share one option parser that
 * accepts exactly the options of the command's help table (cli_help.h), so --help, the man
 * page, the bash completion and the parser cannot disagree. See cmd_basic.h. */
#include "cmd_basic.h"

#include "analysis.h"
#include "run_file.h"
#include "biaxial.h"
#include "cmd_plot.h"
#include "cdem2d.h"
#include "outfile.h"
#include "qexport.h"
#include "quantity.h"
#include "sspx.h"
#include "xdmf.h"

#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

enum { EXIT_OK = 0, EXIT_ERROR = 1, EXIT_USAGE = 2 };

/* Parsed options shared by the subcommands (each accepts the ones its help lists). */
typedef struct {
    const char *cmd; /* subcommand word, for messages */
    const cdem_cli_help *help;
    const char *file;       /* positional: the run file (or cdem2D folder for import) */
    const char *dir;        /* second positional: output directory (export-sspx) */
    const char *increment;  /* --increment K|last|equil|first|all */
    const char *increments; /* --increments A-B */
    const char *quantity;   /* --quantity NAME */
    const char *format;     /* --format csv|h5 */
    const char *out;        /* -o OUT */
    const char *prefix;     /* --prefix P */
    const char *element;    /* --element ID */
    int xdmf2;              /* --xdmf2 */
    int json;               /* --json */
} options;

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

static int usage_error(const options *o, const char *what) {
    cdem_cli_usage_print(stderr, o->help, what);
    return EXIT_USAGE;
}

static int open_run(const options *o, cdem_analysis **a) {
    cdem_error err;
    if (!o->file)
        return usage_error(o, "missing the run file (RUN.h5)");
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

/* s as a JSON string (quotes, escapes; control characters as \u00XX). */
static void json_string(FILE *f, const char *s) {
    fputc('"', f);
    for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
        if (*c == '"' || *c == '\\')
            fprintf(f, "\\%c", *c);
        else if (*c == '\n')
            fputs("\\n", f);
        else if (*c == '\t')
            fputs("\\t", f);
        else if (*c < 0x20)
            fprintf(f, "\\u%04x", *c);
        else
            fputc(*c, f);
    }
    fputc('"', f);
}

/* A number, or null for NaN and infinities (JSON has neither). */
static void json_number(FILE *f, double v) {
    if (isfinite(v))
        fprintf(f, "%.17g", v);
    else
        fputs("null", f);
}

/* info --json: the same facts as the text, for scripts (docs/analysis.md). */
static int info_json(const options *o) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (!o->file)
        return usage_error(o, "missing the run file (RUN.h5)");
    if (cdem_h5_reader_open(o->file, &r, &err) != CDEM_OK)
        return fail_with(&err);
    const size_t n = cdem_h5_reader_increment_count(r);
    size_t equil = 0;
    const int has_equil =
        n > 0 && cdem_h5_reader_find_increment(r, "equil", &equil, &err) == CDEM_OK;
    FILE *f = stdout;
    fputs("{\n  \"file\": ", f);
    json_string(f, o->file);
    fprintf(f, ",\n  \"format_version\": %d,\n  \"program_version\": ",
            cdem_h5_reader_format_version(r));
    json_string(f, cdem_h5_reader_program_version(r));
    fputs(",\n  \"source\": ", f);
    json_string(f, cdem_h5_reader_source(r));
    fputs(",\n  \"created\": ", f);
    json_string(f, cdem_h5_reader_created(r));
    fprintf(f,
            ",\n  \"seed\": %ld,\n  \"unclosed\": %s,\n  \"stop_reason\": ", cdem_h5_reader_seed(r),
            cdem_h5_reader_unclosed(r) ? "true" : "false");
    json_string(f, cdem_h5_reader_stop_reason(r));
    fputs(",\n  \"stop_detail\": ", f);
    json_string(f, cdem_h5_reader_stop_detail(r));
    fputs(",\n  \"summary\": ", f);
    json_string(f, cdem_h5_reader_summary(r));
    fprintf(f, ",\n  \"increment_count\": %zu", n);
    cdem_status st = CDEM_OK;
    cdem_increment_info first = {0}, last = {0}, eq = {0};
    if (n > 0) {
        st = cdem_h5_reader_increment_info(r, 0, &first, &err);
        if (st == CDEM_OK)
            st = cdem_h5_reader_increment_info(r, n - 1, &last, &err);
        if (st == CDEM_OK && has_equil)
            st = cdem_h5_reader_increment_info(r, equil, &eq, &err);
    }
    if (n > 0)
        fprintf(f, ",\n  \"first_increment\": %d,\n  \"last_increment\": %d", (int)first.number,
                (int)last.number);
    if (has_equil)
        fprintf(f, ",\n  \"end_of_equilibration\": %d", (int)eq.number);
    fputs(",\n  \"increments\": [", f);
    for (size_t k = 0; k < n && st == CDEM_OK; k++) {
        cdem_increment_info in;
        st = cdem_h5_reader_increment_info(r, k, &in, &err);
        if (st != CDEM_OK)
            break;
        fprintf(f, "%s\n    {\"number\": %d, \"step\": %lld, \"time\": ", k ? "," : "",
                (int)in.number, (long long)in.step);
        json_number(f, in.time);
        fprintf(f, ", \"phase\": \"%s\", \"net_displacement\": ", phase_name(in.phase));
        json_number(f, in.net_displacement);
        fputs(", \"axial_strain\": ", f);
        json_number(f, in.axial_strain);
        fputs(", \"differential_stress\": ", f);
        json_number(f, in.differential_stress);
        fputs(", \"sea_level\": ", f);
        json_number(f, in.sea_level);
        fprintf(f, ", \"elements\": %lld, \"has_stress\": %s}", (long long)in.n_elements,
                in.has_stress ? "true" : "false");
    }
    fputs(n ? "\n  ]\n}\n" : "]\n}\n", f);
    cdem_h5_reader_close(r);
    return st == CDEM_OK ? EXIT_OK : fail_with(&err);
}

static int cmd_info(const options *o) {
    if (o->json)
        return info_json(o);
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
    /* the counts of the summary and the progress line (docs/format.md, "Counting") */
    const size_t n_inc = cdem_analysis_count(a);
    printf("increments: %zu, numbered %d..%d (end of equilibration: increment %d)\n", n_inc,
           (int)cdem_analysis_info(a, 0)->number, (int)cdem_analysis_info(a, n_inc - 1)->number,
           (int)cdem_analysis_info(a, cdem_analysis_equil_index(a))->number);
    printf("%9s %12s %12s %-13s %14s %9s\n", "increment", "step", "time_s", "phase", "net_displ_m",
           "elements");
    /* an imported cdem2D folder has no step, time or displacement: "-" rather than zeros */
    const int imported = !strncmp(cdem_h5_reader_source(r), "cdem2d-import:", 14);
    for (size_t k = 0; k < cdem_analysis_count(a); k++) {
        const cdem_increment_info *in = cdem_analysis_info(a, k);
        if (imported)
            printf("%9d %12s %12s %-13s %14s %9lld\n", (int)in->number, "-", "-",
                   phase_name(in->phase), "-", (long long)in->n_elements);
        else
            printf("%9d %12lld %12.3f %-13s %14.3f %9lld\n", (int)in->number, (long long)in->step,
                   in->time, phase_name(in->phase), in->net_displacement,
                   (long long)in->n_elements);
    }
    cdem_analysis_close(a);
    return EXIT_OK;
}

/* ---------------------------------------------------------------- compute */
static int cmd_compute(const options *o) {
    if (!o->increment)
        return usage_error(o, "compute needs --increment K|last|equil|first|all");
    if (!o->quantity)
        return usage_error(o, "compute needs --quantity NAME (see 'cdem-strain quantities')");
    const char *format = o->format ? o->format : "csv";
    if (strcmp(format, "csv") != 0 && strcmp(format, "h5") != 0)
        return usage_error(o, "--format must be csv or h5");
    if (strcmp(format, "h5") == 0 && !o->out)
        return usage_error(o, "--format h5 needs -o OUT.h5");
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
    /* "all" skips increments without stress; with none at all that is an error, found before
     * anything is written (on stdout a header followed by an error is a broken CSV) */
    size_t with_stress = 0;
    for (size_t k = first; k <= last; k++)
        with_stress += cdem_analysis_info(a, k)->has_stress != 0;
    if (st == CDEM_OK && q->needs_stress && all && with_stress == 0)
        st = CDEM_FAIL(&err, CDEM_ERR_NOTFOUND,
                       "quantity '%s' needs stress, but no increment of %s stores any (run with "
                       "physics.calculate_stress = on)",
                       q->name, o->file);
    int header_done = h != NULL; /* the CSV header goes out with the first computed rows */
    for (size_t k = first; k <= last && st == CDEM_OK; k++) {
        const cdem_increment_info *in = cdem_analysis_info(a, k);
        if (q->needs_stress && !in->has_stress && all)
            continue;
        const cdem_state *s;
        double *v;
        st = cdem_analysis_values(a, k, q, &s, &v, &err);
        if (st != CDEM_OK)
            break;
        if (!header_done) {
            st = cdem_qexport_csv_header(f, all, &err);
            header_done = 1;
        }
        if (st == CDEM_OK)
            st = h ? cdem_qexport_h5_write(h, in->number, in->time, s, v, &err)
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
    if (st == CDEM_OK && strcmp(format, "h5") == 0) /* its sidecar, once the file has its name */
        st = cdem_qexport_write_xdmf(o->out, NULL, CDEM_XDMF3, NULL, &err);
    cdem_analysis_close(a);
    return st == CDEM_OK ? EXIT_OK : fail_with(&err);
}

/* ---------------------------------------------------------------- element */
static int cmd_element(const options *o) {
    if (!o->increment || !o->element)
        return usage_error(o, "element needs --increment K and --element ID");
    char *end;
    long id = strtol(o->element, &end, 10);
    if (*end || end == o->element)
        return usage_error(o, "--element must be an element id (a whole number)");
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
        return usage_error(o, "limits needs --increment K and --quantity NAME");
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
        return usage_error(o, "export-sspx needs --increments A-B (e.g. 56-282, equil-last)");
    if (!o->dir)
        return usage_error(o, "export-sspx needs an output directory");
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
    if (st == CDEM_OK) /* after the run file and range are known good: no stray folder */
        st = cdem_outfile_make_dirs(o->dir, &err);
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
        return usage_error(o, "export-biaxial needs -o OUT.txt");
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
        return usage_error(o, "import-cdem2d needs the cdem2D folder");
    if (!o->out)
        return usage_error(o, "import-cdem2d needs -o OUT.h5");
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

/* ---------------------------------------------------------------- series */
/* The /series columns in file order (docs/format.md). */
/* clang-format off */
static const char *const series_names[] = {
    "step", "time", "kinetic_energy", "contacts", "bonds", "n_elements", "net_displacement",
    "boundary_force_x", "boundary_force_y", "base_force_x", "base_force_y", "axial_strain",
    "differential_stress", "sea_level"};
/* clang-format on */
#define N_SERIES_NAMES (sizeof series_names / sizeof series_names[0])

static int cmd_series(const options *o) {
    if (!o->file)
        return usage_error(o, "missing the run file (RUN.h5)");
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(o->file, &r, &err) != CDEM_OK)
        return fail_with(&err);
    cdem_series_sample *smp = NULL;
    size_t n = 0;
    double *cols = NULL;
    cdem_status st = cdem_h5_reader_read_series(r, &smp, &n, &err);
    cdem_h5_reader_close(r);
    if (st == CDEM_OK && !(cols = malloc((n ? n : 1) * N_SERIES_NAMES * sizeof *cols)))
        st = CDEM_FAIL(&err, CDEM_ERR_NOMEM, "out of memory for %zu samples", n);
    for (size_t c = 0; c < N_SERIES_NAMES && st == CDEM_OK; c++)
        st = cdem_cmd_plot_column(smp, n, series_names[c], cols + c * n, NULL, &err);
    FILE *f = stdout;
    cdem_outfile of = {.active = 0}; /* -o OUT: written to OUT.tmp, renamed on success */
    if (st == CDEM_OK && o->out) {
        st = cdem_outfile_begin(&of, o->out, &err);
        if (st == CDEM_OK && !(f = fopen(of.tmp, "w")))
            st = CDEM_FAIL(&err, CDEM_ERR_IO, "cannot create %s: %s", of.tmp, strerror(errno));
    }
    if (st == CDEM_OK) {
        for (size_t c = 0; c < N_SERIES_NAMES; c++)
            fprintf(f, "%s%s", c ? "," : "", series_names[c]);
        fputc('\n', f);
        for (size_t k = 0; k < n; k++)
            for (size_t c = 0; c < N_SERIES_NAMES; c++) {
                const double v = cols[c * n + k];
                if (isfinite(v))
                    fprintf(f, "%s%.17g", c ? "," : "", v);
                else
                    fprintf(f, "%snan", c ? "," : "");
                if (c + 1 == N_SERIES_NAMES)
                    fputc('\n', f);
            }
        if (ferror(f))
            st = CDEM_FAIL(&err, CDEM_ERR_IO, "error writing %s", o->out ? of.tmp : "stdout");
    }
    if (f && f != stdout && fclose(f) != 0 && st == CDEM_OK)
        st = CDEM_FAIL(&err, CDEM_ERR_IO, "error writing %s", of.tmp);
    if (of.active)
        st = cdem_outfile_end(&of, st, &err);
    free(cols);
    free(smp);
    return st == CDEM_OK ? EXIT_OK : fail_with(&err);
}

/* ---------------------------------------------------------------- xdmf */
/* 1 when path is a compute --format h5 file (root attribute "quantity"), 0 otherwise. */
static int is_quantity_file(const char *path) {
    int yes = 0;
    H5E_BEGIN_TRY {
        hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
        if (f >= 0) {
            yes = H5Aexists(f, "quantity") > 0;
            H5Fclose(f);
        }
    }
    H5E_END_TRY;
    return yes;
}

static int cmd_xdmf(const options *o) {
    if (!o->file)
        return usage_error(o, "xdmf needs the HDF5 file (RUN.h5, or a compute --format h5 file)");
    cdem_error err;
    char *own = o->out ? NULL : cdem_xdmf_path_for(o->file);
    const char *out = o->out ? o->out : own;
    const int want = o->xdmf2 ? CDEM_XDMF2 : CDEM_XDMF3;
    int written = 0;
    cdem_status st = !out ? CDEM_FAIL(&err, CDEM_ERR_NOMEM, "out of memory")
                     : is_quantity_file(o->file)
                         ? cdem_qexport_write_xdmf(o->file, out, want, &written, &err)
                         : cdem_h5_write_xdmf(o->file, out, want, &written, &err);
    if (st == CDEM_OK) {
        printf("%s\n", out);
        if (written != want)
            fprintf(stderr,
                    "cdem-strain xdmf: note: %s has no xy view (written by an older version) "
                    "or a name with ':' or '|': wrote an XDMF 2 sidecar; ParaView opens it with "
                    "its legacy \"XDMF Reader\"\n",
                    o->file);
    }
    free(own);
    return st == CDEM_OK ? EXIT_OK : fail_with(&err);
}

/* ---------------------------------------------------------------- help tables */
static const char *const info_forms[] = {"RUN.h5 [--json]", NULL};
static const cdem_cli_option info_options[] = {
    {"--json", NULL,
     "the same as one JSON object: file facts, stop reason, summary, counts and one "
     "object per increment (NaN as null)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_info_help = {
    .program = "cdem-strain info",
    .forms = info_forms,
    .about = "Prints the run's summary (as cdem-run --summary printed it), its stop reason and "
             "the list of increments with step, time, phase, net displacement and element "
             "count. Works on a file that is still being written.",
    .options = info_options,
};

static const char *const compute_forms[] = {
    "RUN.h5 --increment K|last|equil|first|all --quantity NAME [--format csv|h5] [-o OUT]", NULL};
static const cdem_cli_option compute_options[] = {
    {"--increment", "K|last|equil|first|all",
     "the increment (a number, first, last, equil = the end of equilibration), or all"},
    {"--quantity", "NAME", "what to compute ('cdem-strain quantities' lists the names)"},
    {"--format", "csv|h5",
     "CSV id,x,y,value (increment,id,x,y,value with --increment all; default) or HDF5 "
     "(needs -o; a .xmf sidecar is written next to it)"},
    {"-o, --output", "OUT", "output file (default: CSV on standard output)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_compute_help = {
    .program = "cdem-strain compute",
    .forms = compute_forms,
    .about = "Per-element values of one quantity (displacement, strain, stress, ...) at one "
             "increment or every increment. 'cdem-strain RUN.h5 --increment K --quantity NAME' "
             "is the same command. Formulas: docs/analysis.md.",
    .options = compute_options,
};

static const char *const element_forms[] = {"RUN.h5 --increment K --element ID", NULL};
static const cdem_cli_option element_options[] = {
    {"--increment", "K|last|equil|first", "the increment"},
    {"--element", "ID", "the element's id (stable for the whole run)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_element_help = {
    .program = "cdem-strain element",
    .forms = element_forms,
    .about = "Coordinates, radius, layer, birth increment and every applicable quantity of one "
             "element (the original program's option-click).",
    .options = element_options,
};

static const char *const limits_forms[] = {"RUN.h5 --increment K --quantity NAME", NULL};
static const cdem_cli_option limits_options[] = {
    {"--increment", "K|last|equil|first", "the increment"},
    {"--quantity", "NAME", "the quantity ('cdem-strain quantities' lists the names)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_limits_help = {
    .program = "cdem-strain limits",
    .forms = limits_forms,
    .about = "The colour-bar limits render uses for a quantity at an increment: minimum, "
             "maximum, the 0.1 x maximum threshold and the colour scale (docs/analysis.md, "
             "\"Colour limits\").",
    .options = limits_options,
};

static const char *const sspx_forms[] = {"RUN.h5 --increments A-B [--prefix P] DIR", NULL};
static const cdem_cli_option sspx_options[] = {
    {"--increments", "A-B",
     "increment range; numbers or first, last, equil on either side (e.g. 56-282, "
     "equil-last)"},
    {"--prefix", "P", "file-name prefix (default: output.prefix of the run, else cdem)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_export_sspx_help = {
    .program = "cdem-strain export-sspx",
    .forms = sspx_forms,
    .about = "One SSPX text file per increment, DIR/<prefix><number>.txt, columns id x y radius "
             "layer (docs/formats-text.md); DIR is created when it does not exist.",
    .options = sspx_options,
};

static const char *const biaxial_forms[] = {"RUN.h5 -o OUT.txt", NULL};
static const cdem_cli_option biaxial_options[] = {{"-o, --output", "OUT.txt", "output file"},
                                                  {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_export_biaxial_help = {
    .program = "cdem-strain export-biaxial",
    .forms = biaxial_forms,
    .about = "The time series of a biaxial test as text: time step, axial strain, differential "
             "stress (N/m) (docs/formats-text.md).",
    .options = biaxial_options,
};

static const char *const import_forms[] = {"DIR -o OUT.h5", NULL};
static const cdem_cli_option import_options[] = {
    {"-o, --output", "OUT.h5", "the cdem file to write (with its .xmf sidecar)"},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_import_cdem2d_help = {
    .program = "cdem-strain import-cdem2d",
    .forms = import_forms,
    .about = "Converts a cdem2D simulation folder (modelresults_N.txt, optional "
             "modelforces_N.txt and modelparameters.txt) into a cdem file that every other "
             "command reads (docs/formats-text.md).",
    .options = import_options,
};

static const char *const series_forms[] = {"RUN.h5 [-o OUT.csv]", NULL};
static const cdem_cli_option series_options[] = {
    {"-o, --output", "OUT.csv", "output file (default: standard output)"}, {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_series_help = {
    .program = "cdem-strain series",
    .forms = series_forms,
    .about = "The run's whole time series (/series) as CSV: a header of the column names (step, "
             "time, kinetic_energy, contacts, bonds, n_elements, net_displacement, "
             "boundary_force_x, boundary_force_y, base_force_x, base_force_y, axial_strain, "
             "differential_stress, sea_level; units in docs/format.md), then one line per "
             "sample, full precision, nan for sea_level without sedimentation.",
    .options = series_options,
};

static const char *const xdmf_forms[] = {"FILE.h5 [-o OUT.xmf] [--xdmf2]", NULL};
static const cdem_cli_option xdmf_options[] = {
    {"-o, --output", "OUT.xmf",
     "the sidecar (default: next to FILE.h5, run.h5 -> run.xmf); it names FILE.h5 by its name "
     "when both are in one folder, else by its absolute path"},
    {"--xdmf2", NULL, "XDMF 2 instead of 3, for VisIt and ParaView's legacy \"XDMF Reader\""},
    {NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_xdmf_help = {
    .program = "cdem-strain xdmf",
    .forms = xdmf_forms,
    .about = "Writes the XDMF sidecar that lets ParaView (and VisIt, with --xdmf2) open a run "
             "file or a compute --format h5 file: after renaming or moving the file, or for "
             "the other flavour. cdem-run and compute write one themselves (docs/format.md, "
             "\"XDMF sidecar\"). Prints the sidecar's name.",
    .options = xdmf_options,
};

static const char *const quantities_forms[] = {"", NULL};
static const cdem_cli_option quantities_options[] = {{NULL, NULL, NULL}};
const cdem_cli_help cdem_cmd_quantities_help = {
    .program = "cdem-strain quantities",
    .forms = quantities_forms,
    .about = "Lists every quantity name with its unit, colour scale and label; those marked "
             "\"needs stress\" need a run with physics.calculate_stress = on.",
    .options = quantities_options,
};

/* ---------------------------------------------------------------- parsing */
/* Where each option's value goes, by its long name. */
static const struct {
    const char *name;
    size_t offset;
} option_fields[] = {
    {"--increment", offsetof(options, increment)}, {"--increments", offsetof(options, increments)},
    {"--quantity", offsetof(options, quantity)},   {"--format", offsetof(options, format)},
    {"--output", offsetof(options, out)},          {"--prefix", offsetof(options, prefix)},
    {"--element", offsetof(options, element)}};

static const struct {
    const char *name;
    size_t offset;
} switch_fields[] = {{"--xdmf2", offsetof(options, xdmf2)}, {"--json", offsetof(options, json)}};

/* Fills o from argv[first..]: only the options of h's table; positional arguments are the
 * file, then the directory. Returns EXIT_OK or EXIT_USAGE (message printed). */
static int parse_options(int argc, char **argv, int first, const char *cmd, const cdem_cli_help *h,
                         options *o) {
    memset(o, 0, sizeof *o);
    o->cmd = cmd;
    o->help = h;
    for (int i = first; i < argc; i++) {
        const char *arg = argv[i], *val;
        const cdem_cli_option *opt = cdem_cli_find_option(h, arg, &val);
        if (opt && !opt->arg) { /* a switch */
            size_t f = 0;
            while (f < sizeof switch_fields / sizeof switch_fields[0] &&
                   !cdem_cli_option_is(opt, switch_fields[f].name))
                f++;
            if (f == sizeof switch_fields / sizeof switch_fields[0])
                return usage_error(o, "internal: a switch of the help table has no field");
            *(int *)((char *)o + switch_fields[f].offset) = 1;
            continue;
        }
        if (opt) {
            if (!val && i + 1 < argc)
                val = argv[++i];
            if (!val) {
                char msg[160];
                snprintf(msg, sizeof msg, "option %.100s needs a value (%s)", arg, opt->arg);
                return usage_error(o, msg);
            }
            size_t f = 0;
            while (f < sizeof option_fields / sizeof option_fields[0] &&
                   !cdem_cli_option_is(opt, option_fields[f].name))
                f++;
            if (f == sizeof option_fields / sizeof option_fields[0])
                return usage_error(o, "internal: an option of the help table has no field");
            *(const char **)((char *)o + option_fields[f].offset) = val;
            continue;
        }
        if (arg[0] == '-' && arg[1]) {
            char msg[160];
            snprintf(msg, sizeof msg, "unknown option '%.100s'", arg);
            return usage_error(o, msg);
        }
        if (!o->file)
            o->file = arg;
        else if (!o->dir && h == &cdem_cmd_export_sspx_help)
            o->dir = arg;
        else {
            char msg[160];
            snprintf(msg, sizeof msg, "unexpected argument '%.100s'", arg);
            return usage_error(o, msg);
        }
    }
    return EXIT_OK;
}

static int run_command(int argc, char **argv, const cdem_cli_help *h, int (*fn)(const options *)) {
    options o;
    int rc = parse_options(argc, argv, 1, argv[0], h, &o);
    return rc ? rc : fn(&o);
}

int cdem_cmd_compute_file_first(int argc, char **argv) {
    options o;
    int rc = parse_options(argc, argv, 0, "compute", &cdem_cmd_compute_help, &o);
    return rc ? rc : cmd_compute(&o);
}

int cdem_cmd_info(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_info_help, cmd_info);
}
int cdem_cmd_compute(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_compute_help, cmd_compute);
}
int cdem_cmd_element(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_element_help, cmd_element);
}
int cdem_cmd_limits(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_limits_help, cmd_limits);
}
int cdem_cmd_export_sspx(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_export_sspx_help, cmd_export_sspx);
}
int cdem_cmd_export_biaxial(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_export_biaxial_help, cmd_export_biaxial);
}
int cdem_cmd_import_cdem2d(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_import_cdem2d_help, cmd_import_cdem2d);
}
int cdem_cmd_series(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_series_help, cmd_series);
}
int cdem_cmd_xdmf(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_xdmf_help, cmd_xdmf);
}
int cdem_cmd_quantities(int argc, char **argv) {
    return run_command(argc, argv, &cdem_cmd_quantities_help, cmd_quantities);
}
