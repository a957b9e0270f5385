/* cmd_info: `cdem-strain info`; its help (below) says what it does. */
#include "cmd_options.h"

#include "analysis.h"
#include "fault_timeline.h"
#include "run_file.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *phase_name(int phase) {
    return phase == CDEM_PHASE_EQUILIBRATION ? "equilibration"
           : phase == CDEM_PHASE_DEFORMATION ? "deformation"
           : phase == CDEM_PHASE_SETTLING    ? "settling"
                                             : "unknown";
}

/* How the run stands. The stop reason recorded, except that a file still saying "running"
 * that no writer holds (runlock.h: its lock is free) was interrupted: its writer was killed
 * or crashed before it could record how the run ended (issue 35, item 9: info said
 * "running", as for a live run); the detail then says what can be done with it. */
typedef struct {
    const char *reason; /* the stop reason to show */
    char detail[2200];  /* the detail to show */
    int interrupted;    /* 1: "running" recorded and no writer holds the file */
} run_state;

static void run_state_of(cdem_h5_reader *r, const char *path, run_state *rs) {
    const char *reason = cdem_h5_reader_stop_reason(r), *detail = cdem_h5_reader_stop_detail(r);
    const int alive = cdem_h5_reader_writer_alive(r);
    rs->interrupted = !strcmp(reason, "running") && alive == 0;
    rs->reason = rs->interrupted ? "interrupted" : reason[0] ? reason : "(none recorded)";
    if (!rs->interrupted) {
        snprintf(rs->detail, sizeof rs->detail, "%s",
                 !strcmp(reason, "running") && alive < 0
                     ? "whether a writer still holds it cannot be told here (the filesystem has "
                       "no locks): interrupted if none does"
                     : detail);
        return;
    }
    /* what --resume needs: a cdem-run file of version 2 with a checkpoint */
    const int cdem_run =
        !strcmp(cdem_h5_reader_source(r), "cdem-run") && cdem_h5_reader_format_version(r) >= 2;
    int32_t at = -1;
    cdem_error err;
    cdem_snapshot *snap = NULL;
    const int resumable = cdem_run && cdem_snapshot_alloc(&snap, &err) == CDEM_OK &&
                          cdem_h5_reader_read_checkpoint(r, snap, &at, &err) == CDEM_OK;
    cdem_snapshot_free(snap);
    if (resumable)
        snprintf(rs->detail, sizeof rs->detail, "continue with cdem-run --resume %s", path);
    else if (cdem_run)
        snprintf(rs->detail, sizeof rs->detail,
                 "it cannot be resumed: its writer was killed before the first checkpoint; run "
                 "it again");
    else
        snprintf(rs->detail, sizeof rs->detail,
                 "it cannot be resumed (written by %s, not cdem-run): write it again",
                 cdem_h5_reader_source(r)[0] ? cdem_h5_reader_source(r) : "an unknown program");
}

/* The "stop reason: ..." line: "interrupted (no writer holds it): continue with cdem-run
 * --resume RUN.h5" for a killed run. */
static void print_stop(cdem_h5_reader *r, const char *path) {
    run_state rs;
    run_state_of(r, path, &rs);
    printf("\nstop reason: %s%s%s%s\n", rs.reason, rs.interrupted ? " (no writer holds it)" : "",
           rs.detail[0] ? ": " : "", rs.detail);
}

/* The "damaged: ..." line of a file whose commit record has damaged rows (issue 46): which
 * rows, which increments they cost; the same text as the reader's warning on stderr. */
static void print_damage(const cdem_h5_reader *r, const char *path) {
    const char *d = cdem_h5_reader_damage(r);
    const size_t at = strlen(path); /* the text without "RUN.h5: damaged file: " */
    if (!d[0])
        return;
    if (!strncmp(d, path, at) && d[at] == ':')
        d += at + 2;
    if (!strncmp(d, "damaged file: ", 14))
        d += 14;
    printf("damaged: %s\n", d);
}

/* info on a file without increments yet (a run that has just started, or was killed
 * before its first increment): the stored texts and "increments: 0" (r is closed). */
static int info_without_increments(cdem_h5_reader *r, const char *path) {
    const char *sum = cdem_h5_reader_summary(r);
    printf("%s%s", sum, sum[0] && sum[strlen(sum) - 1] != '\n' ? "\n" : "");
    print_stop(r, path);
    print_damage(r, path);
    printf("increments: 0 (%s)\n",
           cdem_h5_reader_writer_alive(r) == 1 ? "none written yet" : "none was written");
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
/* The boundary actors of a run of several or with a window (nothing otherwise: the output of
 * a run of one actor is as before): mode, where each fault meets the base, its dip, its window
 * in m of the run's boundary displacement and in increments, its displacement so far. */
static void print_actors(const cdem_analysis *a) {
    cdem_timeline_actor t[CDEM_BOUNDARY_ACTORS];
    const int n = cdem_timeline_actors(cdem_analysis_params(a), t);
    if (n == 0 || (n == 1 && !(t[0].start > 0.0) && !(t[0].stop > 0.0)))
        return;
    const size_t count = cdem_analysis_count(a);
    const double run = cdem_timeline_run_displacement(a, count - 1);
    printf("boundary actors: %d (run's boundary displacement so far %.3f m)\n", n, run);
    printf("%-14s %-16s %10s %7s %-22s %-14s %14s\n", "actor", "mode", "x_base_m", "dip_deg",
           "window_m", "increments", "displacement_m");
    for (int j = 0; j < n; j++) {
        char window[48], incs[32], x[24], dip[16];
        if (t[j].stop > 0.0)
            snprintf(window, sizeof window, "%g-%g", t[j].start, t[j].stop);
        else
            snprintf(window, sizeof window, "%g-end", t[j].start);
        /* the increments whose interval the window overlaps (by more than a rounding) */
        int first = -1, last = -1;
        double before = 0.0;
        for (size_t k = 0; k < count; k++) {
            const double r = cdem_timeline_run_displacement(a, k);
            const double eps = 0.01 * (r - before);
            if (r > before && r > t[j].start + eps &&
                (!(t[j].stop > 0.0) || before < t[j].stop - eps)) {
                if (first < 0)
                    first = cdem_analysis_info(a, k)->number;
                last = cdem_analysis_info(a, k)->number;
            }
            before = r;
        }
        if (first < 0)
            snprintf(incs, sizeof incs, "none yet");
        else
            snprintf(incs, sizeof incs, "%d-%d", first, last);
        snprintf(x, sizeof x, t[j].fault ? "%.1f" : "-", t[j].x_base);
        snprintf(dip, sizeof dip, t[j].fault ? "%g" : "-", t[j].dip_deg);
        printf("%-14s %-16s %10s %7s %-22s %-14s %14.3f\n", t[j].section, cdem_mode_name(t[j].mode),
               x, dip, window, incs, cdem_timeline_actor_displacement(&t[j], run));
    }
}

static int info_json(const cdem_cmd_options *o) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (!o->file)
        return cdem_cmd_usage(o->help, "missing the run file (RUN.h5)");
    if (cdem_h5_reader_open(o->file, &r, &err) != CDEM_OK)
        return cdem_cmd_fail(NULL, NULL, &err);
    const size_t n = cdem_h5_reader_increment_count(r);
    size_t equil = 0;
    cdem_error equil_err;
    cdem_error_clear(&equil_err);
    const int has_equil = n > 0 && cdem_h5_reader_equil_end(r, &equil, &equil_err) == CDEM_OK;
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
    run_state rs;
    run_state_of(r, o->file, &rs);
    const int alive = cdem_h5_reader_writer_alive(r);
    fprintf(f,
            ",\n  \"seed\": %ld,\n  \"unclosed\": %s,\n  \"writer_alive\": %s,\n  "
            "\"stop_reason\": ",
            cdem_h5_reader_seed(r), cdem_h5_reader_unclosed(r) ? "true" : "false",
            alive > 0    ? "true"
            : alive == 0 ? "false"
                         : "null");
    json_string(f, rs.reason[0] == '(' ? "" : rs.reason);
    fputs(",\n  \"stop_detail\": ", f);
    if (rs.interrupted) { /* "no writer holds it: continue with cdem-run --resume RUN.h5" */
        char d[2300];
        snprintf(d, sizeof d, "no writer holds it: %s", rs.detail);
        json_string(f, d);
    } else {
        json_string(f, rs.detail);
    }
    fputs(",\n  \"recorded_stop_reason\": ", f);
    json_string(f, cdem_h5_reader_stop_reason(r));
    fputs(",\n  \"damage\": ", f); /* null, or the reader's warning (issue 46) */
    if (cdem_h5_reader_damage(r)[0])
        json_string(f, cdem_h5_reader_damage(r));
    else
        fputs("null", f);
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
    if (has_equil) {
        fprintf(f, ",\n  \"end_of_equilibration\": %d", (int)eq.number);
    } else if (n > 0) { /* not reached, or no equilibration increment: null, and why */
        fputs(",\n  \"end_of_equilibration\": null,\n  \"end_of_equilibration_note\": ", f);
        const size_t at = strlen(o->file); /* the message without "RUN.h5: " */
        json_string(f, !strncmp(equil_err.msg, o->file, at) && equil_err.msg[at] == ':'
                           ? equil_err.msg + at + 2
                           : equil_err.msg);
    }
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
    if (!o->file)
        return cdem_cmd_usage(o->help, "missing the run file (RUN.h5)");
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(o->file, &r, &err) != CDEM_OK)
        return cdem_cmd_fail(NULL, NULL, &err);
    if (cdem_h5_reader_increment_count(r) == 0)
        return info_without_increments(r, o->file);
    cdem_analysis *a;
    if (cdem_analysis_open_reader(r, o->file, &a, &err) != CDEM_OK)
        return cdem_cmd_fail(NULL, NULL, &err); /* the reader is closed */
    printf("%s", cdem_h5_reader_summary(r));
    if (cdem_h5_reader_summary(r)[0] &&
        cdem_h5_reader_summary(r)[strlen(cdem_h5_reader_summary(r)) - 1] != '\n')
        printf("\n");
    print_stop(r, o->file);
    print_damage(r, o->file);
    /* the counts of the summary and the progress line (docs/format.md, "Counting"); the end
     * of equilibration only once known (never the last increment of a run still in it) */
    const size_t n_inc = cdem_analysis_count(a);
    char equil[160];
    if (cdem_analysis_equil_known(a))
        snprintf(equil, sizeof equil, "increment %d",
                 (int)cdem_analysis_info(a, cdem_analysis_equil_index(a))->number);
    else
        snprintf(equil, sizeof equil, "not reached: %s", cdem_analysis_equil_why(a));
    printf("increments: %zu, numbered %d..%d (end of equilibration: %s)\n", n_inc,
           (int)cdem_analysis_info(a, 0)->number, (int)cdem_analysis_info(a, n_inc - 1)->number,
           equil);
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
    if (!imported)
        print_actors(a);
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
             "count; for a run of several boundary actors (or one with a window), then each "
             "actor: its mode, where its fault meets the base, its dip, its window in m of the "
             "run's boundary displacement and in increments, and its displacement so far. "
             "Works on a file that is still being written.",
    .options = info_options,
};

CDEM_SIMPLE_COMMAND(info, "info", "summary, stop reason and the list of increments", 1, cmd_info);
