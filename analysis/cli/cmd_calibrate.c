/* cmd_calibrate: `cdem-strain calibrate`; its help (below) says what it does. The search
 * is calib.h (pure, unit-tested), the simulations calib_runs.h; this file reads the model,
 * names the runs, measures each design point (the Mohr-Coulomb fit of every test of every
 * seed at once, mohr.h) and writes the report, the [material] block and the picture.
 * Nothing is kept between invocations but the work folder: started again, the command
 * finds the finished runs by their stop reason and the search repeats its steps from them
 * (calib.h keeps no state), so it resumes where it stopped. */
#include "calib.h"
#include "calib_runs.h"
#include "cmd_plot.h"
#include "cmd_support.h"
#include "commands.h"
#include "mohr.h"
#include "params.h"

#include <ctype.h>
#include <errno.h>
#include <gsl/gsl_statistics_double.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

static const char *const calibrate_forms[] = {
    "MODEL.ini [--phi DEG] [--cohesion MPA | --ucs MPA] [--phi-tol DEG] [--cohesion-tol MPA] "
    "[--ucs-tol MPA] [--mu-range LO:HI] [--c0-range LO:HI] [--pressures LIST] [--seeds N] "
    "[--check-seeds N] [--series N] [--margin F] [--jobs N] [--nice N] [--slurm SWEEP.sh] "
    "[--work DIR] [--cdem-run PATH] [-s section.key=value]... [-o OUT.png|.pdf|.svg]",
    NULL};
static const cdem_cli_option calibrate_options[] = {
    {"--phi", "DEG", "target friction angle; searched by material.element_friction"},
    {"--phi-tol", "DEG", "accepted difference from --phi (default 1.5)"},
    {"--cohesion", "MPA",
     "target cohesion C of the envelope; searched by material.element_cohesion"},
    {"--cohesion-tol", "MPA", "accepted difference from --cohesion (default 0.5)"},
    {"--ucs", "MPA",
     "target unconfined strength (the peak of the 0 MPa tests) instead of --cohesion"},
    {"--ucs-tol", "MPA", "accepted difference from --ucs (default 1)"},
    {"--mu-range", "LO:HI", "bounds of element_friction (default 0:1)"},
    {"--c0-range", "LO:HI",
     "bounds of element_cohesion, N, searched on a log scale (default the model's C0 / 1000 "
     "to C0 x 100)"},
    {"--pressures", "LIST", "confining pressures in MPa, comma-separated (default 0,5,10,15,20)"},
    {"--seeds", "N",
     "packings per design point: assembly.seed S..S+N-1, S the model's (default 2)"},
    {"--check-seeds", "N",
     "fresh packings the found material is run with again, seeds after the search's (default "
     "1; 0 skips the check)"},
    {"--series", "N", "design points (biaxial series) allowed (default 8)"},
    {"--margin", "F",
     "the search stops within F x each tolerance, leaving the rest for a fresh packing's "
     "scatter (default 0.6)"},
    {"--jobs", "N", "simulations at once (default: the machine's cores)"},
    {"--nice", "N", "niceness of the simulations, 0 to 19 (default 10)"},
    {"--slurm", "SWEEP.sh",
     "run each series as a Slurm job array through this sweep script (examples/slurm/sweep.sh; "
     "sbatch --wait)"},
    {"--work", "DIR", "the work folder, kept (default calibrate-MODEL)"},
    {"--cdem-run", "PATH", "the cdem-run program (default: next to cdem-strain, else on PATH)"},
    {"-s, --set", "section.key=value",
     "an override for every run (repeatable); not of a value calibrate sets itself: "
     "assembly.seed, boundary.confining_pressure, and element_friction or element_cohesion "
     "while searched"},
    {"-o, --output", "OUT.png|.pdf|.svg",
     "stress-strain curves and Mohr circles of the material found (default DIR/calibration.png)"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "cdem-strain calibrate",
    .forms = calibrate_forms,
    .about =
        "Inverse calibration: finds the element friction and cohesion (material.element_"
        "friction, element_cohesion) that give a target friction angle and cohesion (or "
        "unconfined strength) in biaxial tests of MODEL.ini, a biaxial-test parameter file of "
        "your assembly (boundary.mode = biaxial; start from examples/calibration/biaxial.ini). "
        "Each design point is a series of cdem-run biaxial tests (every pressure, every seed), "
        "run in parallel as separate processes, or as a Slurm job array with --slurm, each an "
        "ordinary run file kept in the work folder; the envelope is fitted to all of them "
        "(cdem-strain mohr). The search steps each input by secants on its monotone map (mu "
        "-> phi, C0 -> C), within its bounds, until a point meets every target within the "
        "margin; a target beyond what the bounds reach is refused with the range found. The "
        "material found is then run with fresh seeds. Prints each series, the result with "
        "its fit uncertainties, and a [material] block (also DIR/material.ini; the report in "
        "DIR/calibration.txt). Interrupted, the same command resumes: finished runs are read, "
        "killed ones continued with cdem-run --resume (docs/analysis.md, \"Calibration\"). "
        "Every option is checked before the first run: the inputs and pressures against the "
        "ranges cdem-run allows for the parameters they set.",
    .options = calibrate_options,
    .exit_status = "0 the material is found and its fresh-seed check is within tolerance, 1 "
                   "refused, not found or an error, 2 usage error.",
};

#define MAX_PRESSURES 12
#define MAX_SEEDS     8
#define MAX_POINTS    32

typedef struct {
    const char *model;
    double phi, phi_tol, coh, coh_tol, ucs, ucs_tol; /* NaN: no target */
    double mu_lo, mu_hi, c0_lo, c0_hi;               /* NaN: default */
    double pressures[MAX_PRESSURES];                 /* MPa */
    int n_pressures, seeds, check_seeds, series, jobs, nice;
    double margin;
    const char *slurm, *work, *cdem_run, *out;
    const char *sets[CDEM_CALIB_MAX_SETS];
    size_t n_sets;
} cal_args;

/* The report: stdout and DIR/calibration.txt alike. */
typedef struct {
    FILE *file;
} cal_report;

static void say(cal_report *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void say(cal_report *r, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    if (r->file) {
        va_start(ap, fmt);
        vfprintf(r->file, fmt, ap);
        va_end(ap);
    }
    fflush(stdout);
}

/* Whether v, in the option's unit (scale x v in the parameter's), lies in the range cdem-run's
 * parameter table allows section.key; range gets that range in the option's unit. The ranges
 * are the table's (common/params.c), never repeated here. */
static int run_allows(const char *section, const char *key, double v, double scale,
                      const char *unit, char *range, size_t cap) {
    const cdem_param_def *d = cdem_params_find(section, key);
    if (!d) { /* never: the keys are the table's */
        snprintf(range, cap, "unknown");
        return 0;
    }
    char lo[32], hi[32];
    cdem_params_format_number(d->min / scale, lo, sizeof lo);
    cdem_params_format_number(d->max / scale, hi, sizeof hi);
    const char *sp = unit[0] ? " " : "";
    if (isinf(d->max))
        snprintf(range, cap, "%s %s%s%s", d->min_exclusive ? ">" : ">=", lo, sp, unit);
    else if (!d->min_exclusive && !d->max_exclusive)
        snprintf(range, cap, "%s to %s%s%s", lo, hi, sp, unit);
    else
        snprintf(range, cap, "%s %s and %s %s%s%s", d->min_exclusive ? ">" : ">=", lo,
                 d->max_exclusive ? "<" : "<=", hi, sp, unit);
    const double x = v * scale;
    return isfinite(x) && (d->min_exclusive ? x > d->min : x >= d->min) &&
           (isinf(d->max) || (d->max_exclusive ? x < d->max : x <= d->max));
}

/* --mu-range, --c0-range: LO:HI with lo_min <= LO (lo_min < LO when lo_excl) and LO < HI,
 * both within the range cdem-run allows section.key. 0, with msg, when not. */
static int parse_range(const char *opt, const char *v, const char *section, const char *key,
                       const char *unit, int lo_excl, double *lo, double *hi, char *msg,
                       size_t cap) {
    char buf[128];
    snprintf(buf, sizeof buf, "%s", v);
    char *colon = strchr(buf, ':');
    if (colon)
        *colon = '\0';
    if (!colon || !cdem_cmd_parse_number(buf, lo) || !cdem_cmd_parse_number(colon + 1, hi) ||
        (lo_excl ? !(*lo > 0) : !(*lo >= 0)) || !(*lo < *hi)) {
        snprintf(msg, cap, "%s %.100s: must be LO:HI%s%s%s with %s < HI", opt, v,
                 unit[0] ? " (" : "", unit, unit[0] ? ")" : "", lo_excl ? "0 < LO" : "0 <= LO");
        return 0;
    }
    for (int end = 0; end < 2; end++) {
        char range[96];
        const double x = end ? *hi : *lo;
        if (!run_allows(section, key, x, 1, unit, range, sizeof range)) {
            snprintf(msg, cap,
                     "%s %.100s: %s %g is outside the range cdem-run allows for %s.%s: %s", opt, v,
                     end ? "HI" : "LO", x, section, key, range);
            return 0;
        }
    }
    return 1;
}

/* --pressures: 2 to MAX_PRESSURES different numbers (MPa), comma-separated, each within the
 * range cdem-run allows for boundary.confining_pressure (N/m, 1 MPa = 1e6); an empty item
 * is refused, not skipped. 0, with msg, when not. */
static int parse_pressures(const char *v, cal_args *a, char *msg, size_t cap) {
    static const char *const allowed = "give 2 to 12 different numbers >= 0 (MPa), comma-separated";
    a->n_pressures = 0;
    int item = 0;
    for (const char *p = v;; p++) {
        const size_t len = strcspn(p, ",");
        item++;
        char tok[64];
        snprintf(tok, sizeof tok, "%.*s", (int)(len < sizeof tok ? len : sizeof tok - 1), p);
        double x;
        char range[96];
        if (len == 0) {
            snprintf(msg, cap, "--pressures %.100s: item %d is empty; %s", v, item, allowed);
            return 0;
        }
        if (len >= sizeof tok || !cdem_cmd_parse_number(tok, &x)) {
            snprintf(msg, cap, "--pressures %.100s: item %d, '%.30s', is not a number; %s", v, item,
                     tok, allowed);
            return 0;
        }
        if (!run_allows("boundary", "confining_pressure", x, 1e6, "MPa", range, sizeof range)) {
            snprintf(msg, cap,
                     "--pressures %.100s: item %d, %g MPa, is outside the range cdem-run "
                     "allows for boundary.confining_pressure: %s",
                     v, item, x, range);
            return 0;
        }
        for (int k = 0; k < a->n_pressures; k++)
            if (a->pressures[k] == x) {
                snprintf(msg, cap, "--pressures %.100s: item %d, %g MPa, repeats item %d; %s", v,
                         item, x, k + 1, allowed);
                return 0;
            }
        if (a->n_pressures == MAX_PRESSURES) {
            snprintf(msg, cap, "--pressures %.100s: more than 12 items; %s", v, allowed);
            return 0;
        }
        a->pressures[a->n_pressures++] = x;
        p += len;
        if (!*p)
            break;
    }
    if (a->n_pressures < 2) {
        snprintf(msg, cap, "--pressures %.100s: one item only; %s", v, allowed);
        return 0;
    }
    return 1;
}

static int parse_args(int argc, char **argv, cal_args *a) {
    *a = (cal_args){.phi = NAN,
                    .phi_tol = 1.5,
                    .coh = NAN,
                    .coh_tol = 0.5,
                    .ucs = NAN,
                    .ucs_tol = 1.0,
                    .mu_lo = 0,
                    .mu_hi = 1,
                    .c0_lo = NAN,
                    .c0_hi = NAN,
                    .pressures = {0, 5, 10, 15, 20},
                    .n_pressures = 5,
                    .seeds = 2,
                    .check_seeds = 1,
                    .series = 8,
                    .jobs = 0,
                    .nice = 10,
                    .margin = 0.6};
    char msg[400] = "";
    for (int i = 1; i < argc; i++) {
        const cdem_cli_option *o;
        const char *v, *typed = argv[i]; /* the option as spelled, for messages */
        cdem_cmd_arg k = cdem_cmd_next_arg(&help, argc, argv, &i, &o, &v);
        if (k == CDEM_CMD_ARG_USAGE)
            return CDEM_EXIT_USAGE;
        if (k == CDEM_CMD_ARG_POSITIONAL) {
            if (a->model)
                return cdem_cmd_usage(&help, "one model file only");
            a->model = argv[i];
            continue;
        }
        const char *n = o->names;
        int ok = 1;
        if (!strcmp(n, "--phi"))
            ok = cdem_cmd_parse_number(v, &a->phi) && a->phi > 0 && a->phi < 90;
        else if (!strcmp(n, "--phi-tol"))
            ok = cdem_cmd_parse_number(v, &a->phi_tol) && a->phi_tol > 0;
        else if (!strcmp(n, "--cohesion"))
            ok = cdem_cmd_parse_number(v, &a->coh) && a->coh >= 0;
        else if (!strcmp(n, "--cohesion-tol"))
            ok = cdem_cmd_parse_number(v, &a->coh_tol) && a->coh_tol > 0;
        else if (!strcmp(n, "--ucs"))
            ok = cdem_cmd_parse_number(v, &a->ucs) && a->ucs >= 0;
        else if (!strcmp(n, "--ucs-tol"))
            ok = cdem_cmd_parse_number(v, &a->ucs_tol) && a->ucs_tol > 0;
        else if (!strcmp(n, "--mu-range"))
            ok = parse_range("--mu-range", v, "material", "element_friction", "", 0, &a->mu_lo,
                             &a->mu_hi, msg, sizeof msg);
        else if (!strcmp(n, "--c0-range"))
            ok = parse_range("--c0-range", v, "material", "element_cohesion", "N", 1, &a->c0_lo,
                             &a->c0_hi, msg, sizeof msg);
        else if (!strcmp(n, "--pressures"))
            ok = parse_pressures(v, a, msg, sizeof msg);
        else if (!strcmp(n, "--seeds"))
            ok = cdem_cmd_parse_int(v, 1, MAX_SEEDS, &a->seeds);
        else if (!strcmp(n, "--check-seeds"))
            ok = cdem_cmd_parse_int(v, 0, MAX_SEEDS, &a->check_seeds);
        else if (!strcmp(n, "--series"))
            ok = cdem_cmd_parse_int(v, 1, MAX_POINTS, &a->series);
        else if (!strcmp(n, "--margin"))
            ok = cdem_cmd_parse_number(v, &a->margin) && a->margin > 0 && a->margin <= 1;
        else if (!strcmp(n, "--jobs"))
            ok = cdem_cmd_parse_int(v, 1, 256, &a->jobs);
        else if (!strcmp(n, "--nice"))
            ok = cdem_cmd_parse_int(v, 0, 19, &a->nice);
        else if (!strcmp(n, "--slurm"))
            a->slurm = v;
        else if (!strcmp(n, "--work"))
            a->work = v;
        else if (!strcmp(n, "--cdem-run"))
            a->cdem_run = v;
        else if (!strcmp(n, "-o, --output"))
            a->out = v;
        else if (!strcmp(n, "-s, --set")) {
            ok = a->n_sets < CDEM_CALIB_MAX_SETS && strchr(v, '=') && strlen(v) < 96;
            if (ok)
                a->sets[a->n_sets++] = v;
        }
        if (!ok && msg[0]) /* the parser's own message */
            return cdem_cmd_usage(&help, msg);
        if (!ok) {
            char spelled[64];
            snprintf(spelled, sizeof spelled, "%.*s", (int)strcspn(typed, "="), typed);
            snprintf(msg, sizeof msg, "%s %.100s: %s", spelled, v,
                     !strcmp(n, "--phi")           ? "must be a number of degrees in 0..90"
                     : !strcmp(n, "--seeds")       ? "must be a whole number 1 to 8"
                     : !strcmp(n, "--check-seeds") ? "must be a whole number 0 to 8"
                     : !strcmp(n, "--series")      ? "must be a whole number 1 to 32"
                     : !strcmp(n, "--margin")      ? "must be a number in (0, 1]"
                     : !strcmp(n, "--jobs")        ? "must be a whole number 1 to 256"
                     : !strcmp(n, "--nice")        ? "must be a whole number 0 to 19"
                     : !strcmp(n, "-s, --set") ? "must be section.key=value (at most 16 of them)"
                                               : "must be a number > 0 (>= 0 for a target)");
            return cdem_cmd_usage(&help, msg);
        }
    }
    if (!a->model)
        return cdem_cmd_usage(&help, "give the model: a biaxial-test parameter file");
    if (isnan(a->phi) && isnan(a->coh) && isnan(a->ucs))
        return cdem_cmd_usage(&help, "give a target: --phi, --cohesion or --ucs");
    if (!isnan(a->coh) && !isnan(a->ucs))
        return cdem_cmd_usage(&help, "give --cohesion or --ucs, not both (both are set by C0)");
    if (!isnan(a->ucs)) {
        int zero = 0;
        for (int k = 0; k < a->n_pressures; k++)
            zero |= a->pressures[k] == 0;
        if (!zero)
            return cdem_cmd_usage(&help, "--ucs needs 0 among --pressures (the unconfined test)");
    }
    /* every run of a series (and of the fresh-seed check) is one file of one envelope fit
     * and one picture, which read at most CDEM_PLOT_MAX_FILES files */
    const int per_series[2] = {a->seeds, a->check_seeds};
    for (int k = 0; k < 2; k++)
        if (per_series[k] * a->n_pressures > CDEM_PLOT_MAX_FILES) {
            snprintf(msg, sizeof msg,
                     "%s %d with %d --pressures: %d runs per series, at most %d (one envelope "
                     "is fitted to all the runs of a series); give fewer seeds or pressures",
                     k ? "--check-seeds" : "--seeds", per_series[k], a->n_pressures,
                     per_series[k] * a->n_pressures, CDEM_PLOT_MAX_FILES);
            return cdem_cmd_usage(&help, msg);
        }
    /* the values calibrate gives every run itself: an -s of one would override them */
    for (size_t k = 0; k < a->n_sets; k++) {
        static const char *const own[] = {"material.element_friction", "material.element_cohesion",
                                          "assembly.seed", "boundary.confining_pressure"};
        const char *s = a->sets[k];
        size_t len = strcspn(s, "=");
        while (len > 0 && s[len - 1] == ' ')
            len--;
        for (int j = 0; j < 4; j++) {
            if (strlen(own[j]) != len || strncmp(s, own[j], len) != 0)
                continue;
            const int fixed =
                (j == 0 && isnan(a->phi)) || (j == 1 && isnan(a->coh) && isnan(a->ucs));
            if (fixed) /* not searched: the model's value, which -s may set */
                continue;
            snprintf(msg, sizeof msg, "-s %.100s: calibrate sets %s in every run itself (%s)", s,
                     own[j],
                     j == 0   ? "it searches it for --phi; bound it with --mu-range"
                     : j == 1 ? "it searches it for --cohesion or --ucs; bound it with --c0-range"
                     : j == 2 ? "the model's seed S and the --seeds after it; set the seed in "
                                "the model file"
                              : "from --pressures");
            return cdem_cmd_usage(&help, msg);
        }
    }
    if (a->jobs == 0) {
        long cores = sysconf(_SC_NPROCESSORS_ONLN);
        a->jobs = cores > 0 ? (int)cores : 1;
    }
    return 0;
}

/* The model as the runs see it: the file's text and the -s overrides. */
typedef struct {
    cdem_params p;
    char *text;
} cal_model;

static cdem_status load_model(const cal_args *a, cal_model *m, cdem_error *err) {
    cdem_params_defaults(&m->p);
    CDEM_TRY(cdem_params_load(&m->p, a->model, &m->text, err));
    for (size_t k = 0; k < a->n_sets; k++) {
        cdem_status st = cdem_params_override(&m->p, a->sets[k], err);
        if (st != CDEM_OK) {
            cdem_error_prefix(err, "-s %s", a->sets[k]);
            return st;
        }
    }
    if (m->p.mode != CDEM_MODE_BIAXIAL)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: boundary.mode = %s: calibrate runs biaxial tests; give a biaxial "
                         "parameter file of your assembly (boundary.mode = biaxial, the radii, "
                         "unit scaling and constants of your model; start from "
                         "examples/calibration/biaxial.ini)",
                         a->model, cdem_mode_name(m->p.mode));
    if (m->p.material != CDEM_MATERIAL_GRANULAR)
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "%s: material.material = bonded: calibrate searches the granular "
                         "material's element_friction and element_cohesion; set material = "
                         "granular",
                         a->model);
    return CDEM_OK;
}

/* The work folder: made when missing; its model.ini is the model's text with the -s
 * overrides as comments. A folder made for another model (or other overrides) is refused,
 * so that its runs are never taken for this model's. */
static cdem_status prepare_work(const cal_args *a, const cal_model *m, const char *dir,
                                char *model_copy, size_t cap, cdem_error *err) {
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return CDEM_FAIL(err, CDEM_ERR_IO, "--work %s: cannot make the folder: %s", dir,
                         strerror(errno));
    size_t len = strlen(m->text) + 64;
    for (size_t k = 0; k < a->n_sets; k++)
        len += strlen(a->sets[k]) + 32;
    char *want = malloc(len);
    if (!want)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "no memory for the model text");
    int n = snprintf(want, len, "%s%s", m->text,
                     m->text[0] && m->text[strlen(m->text) - 1] != '\n' ? "\n" : "");
    for (size_t k = 0; k < a->n_sets; k++)
        n += snprintf(want + n, len - (size_t)n, "# calibrate -s %s\n", a->sets[k]);
    snprintf(model_copy, cap, "%s/model.ini", dir);
    FILE *f = fopen(model_copy, "r");
    cdem_status st = CDEM_OK;
    if (f) {
        char *have = malloc(len + 2);
        size_t got = have ? fread(have, 1, len + 1, f) : 0;
        fclose(f);
        if (!have || got != strlen(want) || memcmp(have, want, got) != 0)
            st = CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                           "--work %s was made for another model: its model.ini differs from "
                           "%s with these -s overrides; give another --work folder (or remove "
                           "this one)",
                           dir, a->model);
        free(have);
    } else {
        f = fopen(model_copy, "w");
        if (!f || fputs(want, f) == EOF || fclose(f) != 0)
            st = CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s", model_copy);
    }
    free(want);
    return st;
}

/* A number as it goes into a file name: %.4g without '+' ("5e+09" -> "5e09"). */
static void name_number(double v, char *buf, size_t cap) {
    char t[32];
    snprintf(t, sizeof t, "%.4g", v);
    size_t j = 0;
    for (size_t i = 0; t[i] && j + 1 < cap; i++)
        if (t[i] != '+')
            buf[j++] = t[i];
    buf[j] = '\0';
}

/* The runs of design point (mu, c0) for seeds first..first+n-1: every pressure of each. */
static size_t point_runs(const cal_args *a, const char *dir, double mu, double c0, long first,
                         int n_seeds, cdem_calib_run *runs) {
    char smu[32], sc0[32];
    name_number(mu, smu, sizeof smu);
    name_number(c0, sc0, sizeof sc0);
    size_t n = 0;
    for (int s = 0; s < n_seeds; s++)
        for (int k = 0; k < a->n_pressures; k++) {
            cdem_calib_run *r = &runs[n++];
            memset(r, 0, sizeof *r);
            char sp[32];
            name_number(a->pressures[k], sp, sizeof sp);
            snprintf(r->name, sizeof r->name, "biaxial_mu%s_C0-%s_seed%ld_%sMPa", smu, sc0,
                     first + s, sp);
            snprintf(r->path, sizeof r->path, "%s/%s.h5", dir, r->name);
            snprintf(r->sets[0], sizeof r->sets[0], "material.element_friction=%.12g", mu);
            snprintf(r->sets[1], sizeof r->sets[1], "material.element_cohesion=%.12g", c0);
            snprintf(r->sets[2], sizeof r->sets[2], "assembly.seed=%ld", first + s);
            snprintf(r->sets[3], sizeof r->sets[3], "boundary.confining_pressure=%.12g",
                     a->pressures[k] * 1e6);
            r->n_sets = 4;
        }
    return n;
}

/* What one design point measured. */
typedef struct {
    double mu, c0;
    double phi, phi_err, coh, coh_err, ucs, ucs_err; /* deg, MPa; errors standard, NaN unknown */
    size_t n_runs, n_ran;
} cal_measure;

/* Fits the envelope to every run of the point; the unconfined strength is the mean peak of
 * the 0 MPa tests (its standard error over the seeds). */
static cdem_status measure(const cdem_calib_run *runs, size_t n, cal_measure *out,
                           cdem_error *err) {
    if (n > CDEM_PLOT_MAX_FILES)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "%zu runs: at most %d at once", n,
                         CDEM_PLOT_MAX_FILES);
    const char *files[CDEM_PLOT_MAX_FILES];
    for (size_t i = 0; i < n; i++)
        files[i] = runs[i].path;
    cdem_mohr_runs tests;
    cdem_mohr_fit fit;
    cdem_status st = cdem_mohr_read_runs(files, n, &tests, err);
    if (st == CDEM_OK)
        st = cdem_mohr_fit_envelope(tests.sigma3, tests.q, n, &fit, err);
    if (st != CDEM_OK) {
        cdem_mohr_runs_free(&tests);
        return st;
    }
    const double *s3 = tests.sigma3, *q = tests.q;
    out->phi = fit.friction * 180 / M_PI;
    out->phi_err = fit.friction_err * 180 / M_PI;
    out->coh = fit.cohesion / 1e6;
    out->coh_err = fit.cohesion_err / 1e6;
    double ucs[CDEM_PLOT_MAX_FILES]; /* the peaks of the 0 MPa tests, MPa */
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (s3[i] == 0)
            ucs[m++] = q[i] / 1e6;
    out->ucs = m ? gsl_stats_mean(ucs, 1, m) : NAN;
    /* the standard error of the mean: the standard deviation (divided by m - 1) over sqrt(m) */
    out->ucs_err = m > 1 ? gsl_stats_sd_m(ucs, 1, m, out->ucs) / sqrt((double)m) : NAN;
    out->n_runs = n;
    cdem_mohr_runs_free(&tests);
    return CDEM_OK;
}

/* Runs (or finds) and measures one design point. */
static cdem_status run_point(const cal_args *a, const cdem_calib_runner *rn, const char *dir,
                             double mu, double c0, long first_seed, int n_seeds, cal_measure *out,
                             cdem_calib_run *runs, size_t *n_runs, cdem_error *err) {
    size_t n = point_runs(a, dir, mu, c0, first_seed, n_seeds, runs);
    size_t ran = 0;
    CDEM_TRY(cdem_calib_complete(rn, runs, n, &ran, err));
    CDEM_TRY(measure(runs, n, out, err));
    out->mu = mu;
    out->c0 = c0;
    out->n_ran = ran;
    *n_runs = n;
    return CDEM_OK;
}

/* "+- E" of a standard error, or "+- n/a" (two tests: an exact fit) */
static const char *pm(double e, char *buf, size_t cap) {
    if (isfinite(e))
        snprintf(buf, cap, "+- %.2g", e);
    else
        snprintf(buf, cap, "+- n/a");
    return buf;
}

static void say_measure(cal_report *r, const char *label, const cal_measure *m, int ucs) {
    char e1[32], e2[32];
    say(r, "%s mu = %.4g, C0 = %.4g N: phi = %.2f %s deg, C = %.3f %s MPa", label, m->mu, m->c0,
        m->phi, pm(m->phi_err, e1, sizeof e1), m->coh, pm(m->coh_err, e2, sizeof e2));
    if (ucs && isfinite(m->ucs))
        say(r, ", unconfined %.3f %s MPa", m->ucs, pm(m->ucs_err, e1, sizeof e1));
    char counts[96];
    cdem_calib_count_text(m->n_runs, m->n_ran, counts, sizeof counts);
    say(r, " (%s)\n", counts);
}

static double elapsed_since(const struct timespec *t0) {
    struct timespec t1;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    return (double)(t1.tv_sec - t0->tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0->tv_nsec);
}

/* The outputs of a measure in the search's pair order: phi, then C or the unconfined
 * strength. */
static void to_point(const cal_measure *m, int use_ucs, cdem_calib_point *pt) {
    memset(pt, 0, sizeof *pt);
    pt->x[0] = m->mu;
    pt->x[1] = m->c0;
    pt->y[0] = m->phi;
    pt->err[0] = m->phi_err;
    pt->y[1] = use_ucs ? m->ucs : m->coh;
    pt->err[1] = use_ucs ? m->ucs_err : m->coh_err;
}

/* Everything one calibration holds. */
typedef struct {
    const cal_args *a;
    char dir[CDEM_CALIB_PATH_MAX];
    char model_copy[CDEM_CALIB_PATH_MAX + 16];
    char report_path[CDEM_CALIB_PATH_MAX + 32];
    char cdem_run[CDEM_CALIB_PATH_MAX], self[CDEM_CALIB_PATH_MAX];
    double mu0, c00; /* the model's */
    long seed0;      /* the model's seed: the first of the search's */
    int use_ucs;
    double c_target, c_tol; /* the second pair's target (C or unconfined), MPa */
    cdem_calib_problem prob;
    cdem_calib_runner rn;
    cal_report rep;
    cdem_calib_point pts[MAX_POINTS];
    cal_measure meas[MAX_POINTS];
    cdem_calib_run runs[MAX_SEEDS * MAX_PRESSURES];
    size_t n, total_runs;
} cal_state;

/* The model, the work folder, cdem-run and the search problem. */
static cdem_status cal_setup(const cal_args *a, cal_state *c, cdem_error *err) {
    c->a = a;
    cal_model m = {0};
    cdem_status st = load_model(a, &m, err);
    if (a->work) {
        snprintf(c->dir, sizeof c->dir, "%s", a->work);
    } else {
        const char *base = cdem_cmd_base_name(a->model);
        size_t len = strlen(base);
        if (len > 4 && !strcmp(base + len - 4, ".ini"))
            len -= 4;
        snprintf(c->dir, sizeof c->dir, "calibrate-%.*s", (int)len, base);
    }
    /* the seeds of the search and of the fresh-seed check, S..S+N+M-1, are values of
     * assembly.seed too: checked before anything runs */
    char range[96];
    const long last_seed = m.p.seed + a->seeds + a->check_seeds - 1;
    if (st == CDEM_OK &&
        !run_allows("assembly", "seed", (double)last_seed, 1, "", range, sizeof range))
        st = CDEM_FAIL(err, CDEM_ERR_INVALID,
                       "%s: assembly.seed = %ld with --seeds %d and --check-seeds %d: the runs "
                       "would use seeds %ld..%ld, beyond the range cdem-run allows for "
                       "assembly.seed (%s); give the model a smaller seed",
                       a->model, m.p.seed, a->seeds, a->check_seeds, m.p.seed, last_seed, range);
    if (st == CDEM_OK)
        st = cdem_calib_find_cdem_run(a->cdem_run, c->cdem_run, sizeof c->cdem_run, err);
    if (st == CDEM_OK)
        st = prepare_work(a, &m, c->dir, c->model_copy, sizeof c->model_copy, err);
    c->mu0 = m.p.element.friction;
    c->c00 = m.p.element.cohesion;
    c->seed0 = m.p.seed;
    free(m.text);
    CDEM_TRY(st);
    cdem_calib_self(c->self, sizeof c->self);

    /* the search problem: mu -> phi, C0 -> C (or the unconfined strength) */
    c->use_ucs = !isnan(a->ucs);
    c->prob = (cdem_calib_problem){.n_pairs = 2, .budget = (size_t)a->series, .digits = 4};
    c->prob.pair[0] = (cdem_calib_pair){.lo = a->mu_lo,
                                        .hi = a->mu_hi,
                                        .first = fmin(fmax(c->mu0, a->mu_lo), a->mu_hi),
                                        .step = 0.1 * (a->mu_hi - a->mu_lo),
                                        .target = a->phi,
                                        .tol = a->phi_tol * a->margin,
                                        .fixed = isnan(a->phi)};
    double c0_lo = a->c0_lo, c0_hi = a->c0_hi;
    if (isnan(c0_lo)) { /* three decades below the model's C0, two above, within the range
                           cdem-run allows */
        c0_lo = c->c00 > 0 ? c->c00 / 1000 : 1e6;
        c0_hi = c->c00 > 0 ? c->c00 * 100 : 1e12;
        const cdem_param_def *d = cdem_params_find("material", "element_cohesion");
        if (d && c0_hi > d->max)
            c0_hi = d->max;
    }
    c->c_target = c->use_ucs ? a->ucs : a->coh;
    c->c_tol = c->use_ucs ? a->ucs_tol : a->coh_tol;
    c->prob.pair[1] = (cdem_calib_pair){.lo = c0_lo,
                                        .hi = c0_hi,
                                        .log_scale = 1,
                                        .first = fmin(fmax(c->c00, c0_lo), c0_hi),
                                        .step = log(10.0),
                                        .target = c->c_target,
                                        .tol = c->c_tol * a->margin,
                                        .fixed = isnan(c->c_target)};
    if (c->prob.pair[0].fixed)
        c->prob.pair[0].first = c->mu0;
    if (c->prob.pair[1].fixed)
        c->prob.pair[1].first = c->c00;
    CDEM_TRY(cdem_calib_check(&c->prob, err));
    c->rn = (cdem_calib_runner){.cdem_run = c->cdem_run,
                                .model = c->model_copy,
                                .dir = c->dir,
                                .sets = a->sets,
                                .n_sets = a->n_sets,
                                .jobs = a->jobs,
                                .nice = a->nice,
                                .slurm_script = a->slurm,
                                .cdem_strain = c->self,
                                .progress = stdout};
    snprintf(c->report_path, sizeof c->report_path, "%s/calibration.txt", c->dir);
    c->rep.file = fopen(c->report_path, "w");
    if (!c->rep.file)
        return CDEM_FAIL(err, CDEM_ERR_IO, "cannot write %s: %s", c->report_path, strerror(errno));
    return CDEM_OK;
}

static void say_header(cal_state *c) {
    const cal_args *a = c->a;
    cal_report *r = &c->rep;
    say(r, "calibrate %s: work folder %s, cdem-run %s\n", a->model, c->dir, c->cdem_run);
    say(r, "targets:");
    if (!c->prob.pair[0].fixed)
        say(r, " phi = %g +- %g deg (mu in %g..%g)", a->phi, a->phi_tol, a->mu_lo, a->mu_hi);
    else
        say(r, " phi reported (mu = %g fixed)", c->mu0);
    if (!c->prob.pair[1].fixed)
        say(r, ", %s = %g +- %g MPa (C0 in %.4g..%.4g N)", c->use_ucs ? "unconfined" : "C",
            c->c_target, c->c_tol, c->prob.pair[1].lo, c->prob.pair[1].hi);
    else
        say(r, ", C reported (C0 = %.4g N fixed)", c->c00);
    say(r, "; the search stops within %g x the tolerances, after %d series at most\n", a->margin,
        a->series);
    say(r, "each series: pressures");
    for (int k = 0; k < a->n_pressures; k++)
        say(r, "%s%g", k ? ", " : " ", a->pressures[k]);
    say(r, " MPa x seeds %ld..%ld (%d runs), %s\n", c->seed0, c->seed0 + a->seeds - 1,
        a->n_pressures * a->seeds, a->slurm ? "as a Slurm job array" : "as local processes");
}

/* The search: series after series until the search says stop; *step gets its verdict. */
static cdem_status cal_search(cal_state *c, cdem_calib_step *step, cdem_error *err) {
    for (;;) {
        CDEM_TRY(cdem_calib_next(&c->prob, c->pts, c->n, step, err));
        if (step->verdict != CDEM_CALIB_RUN)
            return CDEM_OK;
        if (c->n == MAX_POINTS) { /* --series is at most MAX_POINTS: never here */
            step->verdict = CDEM_CALIB_BUDGET;
            return CDEM_OK;
        }
        say(&c->rep, "series %zu: mu = %.4g, C0 = %.4g N\n", c->n + 1, step->x[0], step->x[1]);
        size_t nr;
        CDEM_TRY(run_point(c->a, &c->rn, c->dir, step->x[0], step->x[1], c->seed0, c->a->seeds,
                           &c->meas[c->n], c->runs, &nr, err));
        c->total_runs += nr;
        char label[32];
        snprintf(label, sizeof label, "series %zu:", c->n + 1);
        say_measure(&c->rep, label, &c->meas[c->n], c->use_ucs);
        to_point(&c->meas[c->n], c->use_ucs, &c->pts[c->n]);
        if (!isfinite(c->pts[c->n].y[1]))
            return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                             "series %zu: no unconfined strength (no finite peak at 0 MPa)",
                             c->n + 1);
        c->n++;
    }
}

/* The table of the series, for the report. */
static void say_table(cal_state *c) {
    char e1[32], e2[32], e3[32];
    say(&c->rep, "\n| series | mu | C0 (N) | phi (deg) | C (MPa) | unconfined (MPa) | runs |\n");
    say(&c->rep, "|---|---|---|---|---|---|---|\n");
    for (size_t i = 0; i < c->n; i++) {
        const cal_measure *m = &c->meas[i];
        char counts[96];
        cdem_calib_count_text(m->n_runs, m->n_ran, counts, sizeof counts);
        say(&c->rep, "| %zu | %.4g | %.4g | %.2f %s | %.3f %s | %.3f %s | %s |\n", i + 1, m->mu,
            m->c0, m->phi, pm(m->phi_err, e1, sizeof e1), m->coh, pm(m->coh_err, e2, sizeof e2),
            m->ucs, pm(m->ucs_err, e3, sizeof e3), counts);
    }
    say(&c->rep, "\n");
}

/* Says why the search stopped without a material; the exit status. */
static int say_refusal(cal_state *c, const cdem_calib_step *step) {
    const cal_args *a = c->a;
    const int k = (int)step->pair;
    const char *what = k == 0 ? "friction angle" : c->use_ucs ? "unconfined strength" : "cohesion";
    const char *unit = k == 0 ? "deg" : "MPa", *in = k == 0 ? "mu" : "C0";
    if (step->verdict == CDEM_CALIB_UNREACHABLE) {
        const int other = 1 - k;
        const char *oname = other == 0 ? "phi" : c->use_ucs ? "the unconfined strength" : "C";
        char with[160];
        if (c->prob.pair[other].fixed)
            snprintf(with, sizeof with, "with %s fixed at %.4g", other == 0 ? "mu" : "C0",
                     other == 0 ? c->mu0 : c->c00);
        else
            snprintf(with, sizeof with, "with %s on its target (within 2 tolerances)", oname);
        const double target = k == 0 ? a->phi : c->c_target;
        const double tol = k == 0 ? a->phi_tol : c->c_tol;
        const cal_measure *at = &c->meas[step->at];
        const double y_at = c->pts[step->at].y[k];
        say(&c->rep,
            "refused: the target %s %g %s is out of reach. %c%s, %s at its %s bound (%.4g, "
            "series %zu) gives %.3g %s, %s than %g %s %g: %s can go no %s here. Reachable %s "
            "found (series %s): %.3g to %.3g %s.\n",
            what, target, unit, toupper((unsigned char)with[0]), with + 1, in,
            step->above ? "upper" : "lower", k == 0 ? at->mu : at->c0, step->at + 1, y_at, unit,
            step->above ? "less" : "more", target, step->above ? "-" : "+", tol, what,
            step->above ? "higher" : "lower", what, with, step->reach_lo, step->reach_hi, unit);
        fprintf(stderr,
                "cdem-strain calibrate: refused: the target %s %g %s is out of reach (reachable "
                "%s: %.3g to %.3g %s, %s in %.4g..%.4g); see %s\n",
                what, target, unit, with, step->reach_lo, step->reach_hi, unit, in,
                c->prob.pair[k].lo, c->prob.pair[k].hi, c->report_path);
    } else if (step->verdict == CDEM_CALIB_NOT_MONOTONE) {
        const cal_measure *p0 = &c->meas[step->bad[0]], *p1 = &c->meas[step->bad[1]];
        const char *out = k == 0 ? "phi" : c->use_ucs ? "unconfined" : "C";
        say(&c->rep,
            "stopped: %s does not rise with %s here: series %zu (mu = %.4g, C0 = %.4g N) gives "
            "%s = %.3f, series %zu (mu = %.4g, C0 = %.4g N) %s = %.3f, beyond 2 standard "
            "errors; narrow --%s-range, add --seeds, or calibrate by hand there\n",
            out, in, step->bad[0] + 1, p0->mu, p0->c0, out, c->pts[step->bad[0]].y[k],
            step->bad[1] + 1, p1->mu, p1->c0, out, c->pts[step->bad[1]].y[k], k == 0 ? "mu" : "c0");
        fprintf(stderr, "cdem-strain calibrate: %s does not rise with %s here; see %s\n", out, in,
                c->report_path);
    } else {
        say(&c->rep, "not found: %s after %zu series; the best is series %zu\n",
            cdem_calib_verdict_name(step->verdict), c->n, step->best + 1);
        fprintf(stderr,
                "cdem-strain calibrate: no material within the tolerances in %zu series (%s; "
                "--series, --margin); see %s\n",
                c->n, cdem_calib_verdict_name(step->verdict), c->report_path);
    }
    return CDEM_EXIT_ERROR;
}

/* The fresh-seed check of the material found: *ok 1 when within the tolerances. */
static cdem_status cal_check(cal_state *c, const cal_measure *b, cal_measure *chk, int *ok,
                             cdem_error *err) {
    const cal_args *a = c->a;
    *ok = 1;
    if (a->check_seeds == 0)
        return CDEM_OK;
    say(&c->rep, "fresh-seed check: seeds %ld..%ld\n", c->seed0 + a->seeds,
        c->seed0 + a->seeds + a->check_seeds - 1);
    size_t nr;
    CDEM_TRY(run_point(a, &c->rn, c->dir, b->mu, b->c0, c->seed0 + a->seeds, a->check_seeds, chk,
                       c->runs, &nr, err));
    c->total_runs += nr;
    say_measure(&c->rep, "fresh seeds:", chk, c->use_ucs);
    const double d0 = fabs(chk->phi - a->phi);
    const double d1 = fabs((c->use_ucs ? chk->ucs : chk->coh) - c->c_target);
    *ok = (c->prob.pair[0].fixed || d0 <= a->phi_tol) && (c->prob.pair[1].fixed || d1 <= c->c_tol);
    say(&c->rep, "fresh-seed check: %s\n",
        *ok ? "within the tolerances (a property of the material, not of one packing)"
            : "OUTSIDE the tolerances: the packings scatter more than the tolerances allow; use "
              "more --seeds, a smaller --margin or wider tolerances");
    if (!*ok)
        fprintf(stderr,
                "cdem-strain calibrate: the fresh-seed check is outside the tolerances; "
                "see %s\n",
                c->report_path);
    return CDEM_OK;
}

/* The [material] block: on stdout, in the report and in DIR/material.ini. */
static void write_material(cal_state *c, const cal_measure *b, const cal_measure *chk) {
    char mpath[CDEM_CALIB_PATH_MAX + 32], e1[32], e2[32];
    snprintf(mpath, sizeof mpath, "%s/material.ini", c->dir);
    FILE *mf = fopen(mpath, "w");
    FILE *out[3] = {stdout, c->rep.file, mf};
    for (int w = 0; w < 3; w++) {
        FILE *f = out[w];
        if (!f)
            continue;
        fprintf(f,
                "\n[material]\n# cdem-strain calibrate %s: phi = %.2f %s deg, C = %.3f %s MPa "
                "(seeds %ld..%ld",
                c->a->model, b->phi, pm(b->phi_err, e1, sizeof e1), b->coh,
                pm(b->coh_err, e2, sizeof e2), c->seed0, c->seed0 + c->a->seeds - 1);
        if (c->a->check_seeds > 0)
            fprintf(f, "; fresh seeds: phi = %.2f deg, C = %.3f MPa", chk->phi, chk->coh);
        fprintf(f, ")\nelement_friction = %.4g\nelement_cohesion = %.4g\n", b->mu, b->c0);
    }
    if (mf && fclose(mf) == 0)
        say(&c->rep, "(also in %s)\n", mpath);
}

static int calibrate(const cal_args *a) {
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    cdem_error err;
    cal_state *c = calloc(1, sizeof *c);
    if (!c) {
        fprintf(stderr, "cdem-strain calibrate: no memory\n");
        return CDEM_EXIT_ERROR;
    }
    cdem_status st = cal_setup(a, c, &err);
    cdem_calib_step step = {0};
    if (st == CDEM_OK) {
        say_header(c);
        st = cal_search(c, &step, &err);
    }
    int rc = CDEM_EXIT_OK;
    /* a point within the full tolerances (not within the margin) still counts when the
     * budget ran out or the search stalled */
    int found = st == CDEM_OK && step.verdict == CDEM_CALIB_FOUND;
    if (st == CDEM_OK && !found && c->n > 0 &&
        (step.verdict == CDEM_CALIB_BUDGET || step.verdict == CDEM_CALIB_STALLED) &&
        step.best_score <= 1 / a->margin) {
        found = 1;
        say(&c->rep, "(%s: the best series is within the tolerances, not within the margin)\n",
            cdem_calib_verdict_name(step.verdict));
    }
    if (st == CDEM_OK)
        say_table(c);
    if (st == CDEM_OK && !found)
        rc = say_refusal(c, &step);
    if (st == CDEM_OK && c->n > 0) {
        const cal_measure *b = &c->meas[step.best];
        cal_measure chk = {0};
        int ok = 1;
        if (found) {
            say(&c->rep, "found in %zu series (%zu runs):", c->n, c->total_runs);
            say_measure(&c->rep, "", b, c->use_ucs);
            st = cal_check(c, b, &chk, &ok, &err);
            if (st == CDEM_OK)
                write_material(c, b, &chk);
            if (!ok)
                rc = CDEM_EXIT_ERROR;
        } else {
            say(&c->rep, "the nearest series, %zu:", step.best + 1);
            say_measure(&c->rep, "", b, c->use_ucs);
        }
        /* the picture of the best series (found or not) */
        char png[CDEM_CALIB_PATH_MAX + 32];
        snprintf(png, sizeof png, "%s/calibration.png", c->dir);
        const char *out = a->out ? a->out : png;
        size_t np = point_runs(a, c->dir, b->mu, b->c0, c->seed0, a->seeds, c->runs);
        const char *files[CDEM_PLOT_MAX_FILES];
        for (size_t i = 0; i < np; i++)
            files[i] = c->runs[i].path;
        if (st == CDEM_OK)
            st = cdem_cmd_mohr_picture(files, np, out, &err);
        if (st == CDEM_OK)
            say(&c->rep, "picture: %s (series %zu)\n", out, step.best + 1);
    }
    if (st == CDEM_OK)
        say(&c->rep, "series used: %zu, runs: %zu, wall time %.0f s\n", c->n, c->total_runs,
            elapsed_since(&t0));
    if (c->rep.file)
        fclose(c->rep.file);
    if (st != CDEM_OK)
        rc = cdem_cmd_fail("calibrate", NULL, &err);
    free(c);
    return rc;
}

static int cmd_calibrate(int argc, char **argv) {
    cal_args a;
    int rc = parse_args(argc, argv, &a);
    return rc ? rc : calibrate(&a);
}

const cdem_command cdem_command_calibrate = {
    "calibrate", "find the element friction and cohesion that give a target phi and C", &help,
    cmd_calibrate};
