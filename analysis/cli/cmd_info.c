/* cmd_info: `cdem-strain info`; its help (below) says what it does. */
#include "cmd_options.h"

#include "analysis.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *phase_name(int phase) {
    return phase == CDEM_PHASE_EQUILIBRATION ? "equilibration"
           : phase == CDEM_PHASE_DEFORMATION ? "deformation"
           : phase == CDEM_PHASE_SETTLING    ? "settling"
                                             : "unknown";
}

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
    return CDEM_EXIT_OK;
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
static int info_json(const cdem_cmd_options *o) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (!o->file)
        return cdem_cmd_usage(o->help, "missing the run file (RUN.h5)");
    if (cdem_h5_reader_open(o->file, &r, &err) != CDEM_OK)
        return cdem_cmd_fail(NULL, NULL, &err);
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
    return st == CDEM_OK ? CDEM_EXIT_OK : cdem_cmd_fail(NULL, NULL, &err);
}

static int cmd_info(const cdem_cmd_options *o) {
    if (o->json)
        return info_json(o);
    int none = o->file ? info_without_increments(o->file) : -1;
    if (none >= 0)
        return none;
    cdem_analysis *a;
    int rc = cdem_cmd_open_run(o, &a);
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
    return CDEM_EXIT_OK;
}

static const char *const info_forms[] = {"RUN.h5 [--json]", NULL};
static const cdem_cli_option info_options[] = {
    {"--json", NULL,
     "the same as one JSON object: file facts, stop reason, summary, counts and one "
     "object per increment (NaN as null)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain info",
    .forms = info_forms,
    .about = "Prints the run's summary (as cdem-run --summary printed it), its stop reason and "
             "the list of increments with step, time, phase, net displacement and element "
             "count. Works on a file that is still being written.",
    .options = info_options,
};

CDEM_SIMPLE_COMMAND(info, "info", "summary, stop reason and the list of increments", 1, cmd_info);
