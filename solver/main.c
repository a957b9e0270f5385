/* cdem-run: the command line of the solver.
 *
 * Reads a parameter file (or uses the built-in default model), applies -s overrides in
 * command-line order, validates, prints the model summary and runs the simulation through
 * cdem_run() (solver/run/run.h). This is the only place that prints messages and chooses exit
 * codes: 0 completed, 1 error, 2 usage error, 3 interrupted (SIGINT/SIGTERM/SIGHUP; the
 * output file is still valid and records where it stopped). An existing output is never
 * replaced without --force, and a file that is not a cdem run file never. Messages go to stderr as
 * "cdem-run: <message>", one line per problem; the summary and the --print-defaults /
 * --params-markdown (--laws-markdown, --modes-markdown) texts go to stdout so they can be
 * redirected into files. */
#include "bc.h"
#include "h5format.h"
#include "model.h"
#include "params.h"
#include "run.h"
#include "runlock.h"
#include "summary.h"
#include "estimate.h"
#include "cli_help.h"
#include "governor.h"
#include "parallel.h"
#include "threads.h"

#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#ifndef CDEM_VERSION
#define CDEM_VERSION "0.0.0"
#endif

enum { EXIT_OK = 0, EXIT_ERROR = 1, EXIT_USAGE = 2, EXIT_INTERRUPTED = 3 };

/* The one mutable global of the project: a signal handler can only communicate through a
 * static volatile sig_atomic_t. main passes its address to cdem_run as opt.stop_requested;
 * the solver polls it between time steps and stops cleanly. */
static volatile sig_atomic_t stop_requested = 0;

static void on_signal(int sig) {
    (void)sig;
    stop_requested = 1;
}

/* The help text, option table and synopsis of cdem-run (cli_help.h): --help prints it, the
 * man page and the bash completion are generated from it, and tests/test_help.c checks that
 * every option in it appears in the synopsis and is accepted by parse_args. */
static const char *const run_forms[] = {
    "[MODEL.ini|-] [-o OUT.h5] [-s section.key=value]... [-q] [--summary] [--dry-run] "
    "[--print-defaults] [--params-markdown] [--laws-markdown] [--modes-markdown] [--max-steps N] "
    "[--threads N] [--par-min N] [--force] "
    "[--ignore-free-space] [--no-fsync]",
    "--resume RUN.h5 [-q] [--max-steps N] [--threads N] [--par-min N] [--no-fsync]",
    "-V|--version | -h|--help", NULL};

static const cdem_cli_option run_options[] = {
    {"-o", "OUT.h5",
     "output file (default: MODEL's base name with .h5 in the current directory, or "
     "cdem-default.h5 without a model file); an XDMF sidecar OUT.xmf is written next to it; "
     "an existing file is not replaced (see --force), and a file that another run is "
     "writing is refused"},
    {"--force", NULL,
     "replace an existing OUT.h5 that is a cdem run file (never any other file, nor the "
     "parameter or fault file); a completed run it replaces is kept as OUT.h5.replaced until "
     "the new run completes, so a new run that is killed or fails loses nothing"},
    {"-s", "section.key=value", "override one parameter (repeatable; applied after the file)"},
    {"-q, --quiet", NULL, "quiet: no summary, no progress"},
    {"--summary", NULL, "validate, print the model summary and exit"},
    {"--dry-run", NULL, "as --summary, then say that nothing was simulated"},
    {"--print-defaults", NULL,
     "print a complete commented parameter file of the effective values (defaults + file + "
     "overrides) and exit"},
    {"--params-markdown", NULL, "print the parameter table in markdown (docs/parameters.md)"},
    {"--laws-markdown", NULL,
     "print the table of the granular contact laws in markdown (docs/solver.md, section 1)"},
    {"--modes-markdown", NULL,
     "print the table of the boundary modes in markdown (docs/solver.md, section 4)"},
    {"--max-steps", "N",
     "stop after N time steps (tests, benchmarks); the file records \"stopped-early\""},
    {"--resume", "RUN.h5",
     "continue a stopped or killed run from its newest checkpoint "
     "(output.checkpoint_interval); the parameters come from the file, so MODEL.ini, -s and "
     "-o are refused; the result is bit-identical to an uninterrupted run"},
    {"--threads", "N",
     "run on N threads (default: OMP_NUM_THREADS, else one per core); results are identical "
     "for any N. Idle threads sleep at once (OMP_WAIT_POLICY=passive; OMP_WAIT_POLICY or "
     "GOMP_SPINCOUNT, when set, decide instead), and a run that measures 1 thread faster than "
     "N (" GOVERNOR_WHY_ONE ") goes on with 1 until N is faster again "
     "(CDEM_THREAD_GOVERNOR=off keeps N)"},
    {"--par-min", "N",
     "run loops of more than N items on several threads (default " CDEM_PAR_MIN_STR "; results "
     "are identical for any N and thread count)"},
    {"--ignore-free-space", NULL,
     "run even when the output directory has less free space than the estimated file size"},
    {"--no-fsync", NULL,
     "do not flush each committed increment to the disk: faster on slow disks, but a power "
     "cut (not a kill) may lose increments; for throwaway runs"},
    {"-V, --version", NULL, "print the version and exit"},
    {NULL, NULL, NULL}};

static const cdem_cli_help run_help = {
    .program = "cdem-run",
    .forms = run_forms,
    .about = "Simulates a 2-D discrete element model and writes every display increment to an "
             "HDF5 file. Without MODEL.ini the built-in default model is used (the paper's "
             "Figure 7A: 10 x 5 km, planar normal fault dipping 30 degrees); '-' reads the "
             "parameter file from standard input (default output stdin.h5).",
    .options = run_options,
    .notes = "Ctrl-C (SIGINT), SIGTERM or SIGHUP stops the run cleanly after the current step; the "
             "file stays valid and 'cdem-run --resume RUN.h5' continues it. Parameters, "
             "ranges and rules: docs/parameters.md; the user guide: docs/guide.md.",
    .exit_status = "0 completed, 1 error, 2 usage error, 3 interrupted (SIGINT/SIGTERM/SIGHUP: "
                   "the run finishes its time step and records where it stopped).",
};

/* Prints a possibly multi-line message with the program prefix on every line. */
static void print_error(const char *msg) {
    const char *s = msg;
    while (*s) {
        const char *nl = strchr(s, '\n');
        int len = nl ? (int)(nl - s) : (int)strlen(s);
        fprintf(stderr, "cdem-run: %.*s\n", len, s);
        s += len + (nl ? 1 : 0);
    }
    if (!msg[0])
        fprintf(stderr, "cdem-run: unknown error\n");
}

/* fmt has one or two %s: arg and, for the second, hint. */
static int usage_error(const char *fmt, const char *arg, const char *hint) {
    fprintf(stderr, "cdem-run: ");
    fprintf(stderr, fmt, arg, hint);
    fprintf(stderr, "\nTry 'cdem-run --help' for more information.\n");
    return EXIT_USAGE;
}

typedef struct {
    const char *model_path;  /* MODEL.ini or NULL for the default model */
    const char *output_path; /* -o, or NULL for the default name */
    const char **overrides;  /* -s arguments in order (points into argv) */
    int n_overrides;         /* number of -s arguments */
    int quiet;               /* -q */
    int summary_only;        /* --summary */
    int dry_run;             /* --dry-run */
    int print_defaults;      /* --print-defaults */
    int params_markdown;     /* --params-markdown */
    int laws_markdown;       /* --laws-markdown */
    int modes_markdown;      /* --modes-markdown */
    int help, version;       /* -h/--help, --version */
    long max_steps;          /* --max-steps, 0 = no limit */
    const char *resume_path; /* --resume RUN.h5, or NULL */
    long par_min;            /* --par-min, 0 = default */
    int threads;             /* --threads, 0 = OMP_NUM_THREADS or all cores */
    int ignore_free_space;   /* --ignore-free-space */
    int force;               /* --force */
    int no_fsync;            /* --no-fsync */
} cli_args;

/* A whole number > 0 for option opt; refuses trailing text, signs and values that do not
 * fit in a long (strtol would silently give LONG_MAX for a 23-digit number). */
static int parse_count(const char *opt, const char *text, long *out) {
    char *end = NULL;
    errno = 0;
    long n = strtol(text, &end, 10);
    if (end == text || *end != '\0' || text[0] == '-' || text[0] == '+' || n <= 0) {
        fprintf(stderr, "cdem-run: %s %s: expected a whole number > 0\n", opt, text);
        return EXIT_USAGE;
    }
    if (errno == ERANGE) {
        fprintf(stderr, "cdem-run: %s %s: too large (at most %ld)\n", opt, text, LONG_MAX);
        return EXIT_USAGE;
    }
    *out = n;
    return EXIT_OK;
}

/* Returns EXIT_OK or EXIT_USAGE (message already printed). */
static int parse_args(int argc, char **argv, cli_args *a) {
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
            a->help = 1;
        } else if (strcmp(arg, "--version") == 0 || strcmp(arg, "-V") == 0) {
            a->version = 1;
        } else if (strcmp(arg, "-q") == 0 || strcmp(arg, "--quiet") == 0) {
            a->quiet = 1;
        } else if (strcmp(arg, "--summary") == 0) {
            a->summary_only = 1;
        } else if (strcmp(arg, "--dry-run") == 0) {
            a->dry_run = 1;
        } else if (strcmp(arg, "--print-defaults") == 0) {
            a->print_defaults = 1;
        } else if (strcmp(arg, "--params-markdown") == 0) {
            a->params_markdown = 1;
        } else if (strcmp(arg, "--laws-markdown") == 0) {
            a->laws_markdown = 1;
        } else if (strcmp(arg, "--modes-markdown") == 0) {
            a->modes_markdown = 1;
        } else if (strcmp(arg, "-o") == 0) {
            if (i + 1 >= argc)
                return usage_error("option %s needs a file name", arg, NULL);
            a->output_path = argv[++i];
        } else if (strcmp(arg, "-s") == 0) {
            if (i + 1 >= argc)
                return usage_error("option %s needs section.key=value", arg, NULL);
            a->overrides[a->n_overrides++] = argv[++i];
        } else if (strncmp(arg, "-s", 2) == 0 && strchr(arg, '=')) {
            a->overrides[a->n_overrides++] = arg + 2; /* -ssection.key=value */
        } else if (strcmp(arg, "--ignore-free-space") == 0) {
            a->ignore_free_space = 1;
        } else if (strcmp(arg, "--force") == 0) {
            a->force = 1;
        } else if (strcmp(arg, "--no-fsync") == 0) {
            a->no_fsync = 1;
        } else if (strcmp(arg, "--max-steps") == 0) {
            if (i + 1 >= argc)
                return usage_error("option %s needs a number of time steps", arg, NULL);
            if (parse_count(arg, argv[++i], &a->max_steps) != EXIT_OK)
                return EXIT_USAGE;
        } else if (strcmp(arg, "--resume") == 0) {
            if (i + 1 >= argc)
                return usage_error("option %s needs the run file to continue", arg, NULL);
            a->resume_path = argv[++i];
        } else if (strcmp(arg, "--threads") == 0) {
            if (i + 1 >= argc)
                return usage_error("option %s needs a number of threads", arg, NULL);
            if (cdem_threads_parse(argv[++i], &a->threads) != 0)
                return usage_error("--threads %s: expected a whole number from 1 to 1024", argv[i],
                                   NULL);
        } else if (strcmp(arg, "--par-min") == 0) {
            if (i + 1 >= argc)
                return usage_error("option %s needs a number of items", arg, NULL);
            if (parse_count(arg, argv[++i], &a->par_min) != EXIT_OK)
                return EXIT_USAGE;
        } else if (arg[0] == '-' && arg[1] != '\0') {
            char near[64];
            return usage_error(cdem_cli_suggest_option(&run_help, arg, near, sizeof near)
                                   ? "unknown option %s; did you mean %s?"
                                   : "unknown option %s",
                               arg, near);
        } else if (!a->model_path) {
            a->model_path = arg;
        } else {
            return usage_error("more than one model file given (second: %s)", arg, NULL);
        }
    }
    return EXIT_OK;
}

/* "dir/fault.ini" -> "fault.h5" (in the current directory); "-" (standard input) ->
 * "stdin.h5". */
static char *default_output(const char *model_path) {
    if (!model_path)
        return strdup("cdem-default.h5");
    if (!strcmp(model_path, "-"))
        return strdup("stdin.h5");
    const char *base = strrchr(model_path, '/');
    base = base ? base + 1 : model_path;
    const char *dot = strrchr(base, '.');
    size_t stem = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    char *out = malloc(stem + 4);
    if (!out)
        return NULL;
    memcpy(out, base, stem);
    memcpy(out + stem, ".h5", 4);
    return out;
}

/* The parameter text stored in the output: the original file when nothing was overridden,
 * else a complete file of the effective values (so it re-parses to what was run). */
static char *stored_params_text(const cdem_params *p, const cli_args *a, char *file_text) {
    if (a->n_overrides == 0 && file_text)
        return file_text;
    free(file_text);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return NULL;
    fprintf(f, "# effective parameters of this run: %s",
            a->model_path ? a->model_path : "defaults");
    for (int i = 0; i < a->n_overrides; i++)
        fprintf(f, " -s %s", a->overrides[i]);
    fputc('\n', f);
    cdem_params_write_record(p, f);
    fclose(f);
    return buf;
}

/* The whole of standard input (a parameter file), malloc'd into *text. */
static cdem_status read_stdin(char **text, cdem_error *err) {
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    while (buf) {
        size_t got = fread(buf + len, 1, cap - 1 - len, stdin);
        len += got;
        if (got == 0)
            break;
        if (len + 1 == cap) {
            char *nb = cap < ((size_t)64 << 20) ? realloc(buf, cap * 2) : NULL;
            if (!nb) {
                free(buf);
                return CDEM_FAIL(err, CDEM_ERR_PARSE,
                                 "standard input: more than 64 MiB or out of memory; not a "
                                 "parameter file");
            }
            buf = nb;
            cap *= 2;
        }
    }
    if (!buf)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory reading standard input");
    if (ferror(stdin)) {
        free(buf);
        return CDEM_FAIL(err, CDEM_ERR_IO, "error reading the parameters from standard input");
    }
    buf[len] = '\0';
    *text = buf;
    return CDEM_OK;
}

/* SIGINT, SIGTERM and SIGHUP (a closed terminal or ssh session) all stop the run cleanly:
 * the time step finishes, a checkpoint and a final increment are written and the stop
 * reason says "interrupted". SIGXFSZ (a ulimit -f file size limit) would kill the process
 * without a word; ignored, the write fails with EFBIG instead, and the run stops with
 * "write-failure", a message naming the file and every committed increment kept. */
static void install_handlers(void) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);
    sa.sa_handler = SIG_IGN;
    sigaction(SIGXFSZ, &sa, NULL);
}

/* 1 when a and b name the same file: the same text, or the same existing inode. */
static int same_file(const char *a, const char *b) {
    if (!a || !b)
        return 0;
    if (strcmp(a, b) == 0)
        return 1;
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* Refuses an output that is one of the run's inputs, then (before the model is set up, so
 * the refusal is immediate) an output another run is writing or that may not be replaced.
 * The writer repeats the last two checks under its lock. */
static int check_output(const cli_args *a, const cdem_model *m, const char *out, cdem_error *err) {
    const char *inputs[2] = {a->model_path, m->mode.input};
    const char *what[2] = {"the parameter file", m->mode.input_what};
    for (int k = 0; k < 2; k++)
        if (inputs[k] && inputs[k][0] && same_file(out, inputs[k])) {
            fprintf(stderr,
                    "cdem-run: the output file %s is %s %s, an input of this run: it is never "
                    "overwritten; choose another output file with -o\n",
                    out, what[k], inputs[k]);
            return EXIT_USAGE;
        }
    if (cdem_h5_output_check(out, a->force ? CDEM_H5_REPLACE_CDEM : CDEM_H5_REPLACE_NEVER, err) !=
        CDEM_OK) {
        print_error(err->msg);
        return EXIT_ERROR;
    }
    return EXIT_OK;
}

/* --resume: the parameters are those stored in the file; anything that could change the
 * physics (a model file, -s overrides) is refused, as is -o (the file itself continues). */
static int resume(const cli_args *a, cdem_error *err) {
    if (a->model_path || a->n_overrides > 0 || a->output_path || a->summary_only || a->dry_run ||
        a->print_defaults || a->force) {
        fprintf(stderr,
                "cdem-run: --resume %s continues the run with the parameters stored in the file; "
                "it cannot be combined with %s (they could change the results; a resumed run is "
                "bit-identical to an uninterrupted one)\n",
                a->resume_path,
                a->model_path        ? "a model file"
                : a->n_overrides > 0 ? "-s overrides"
                : a->output_path     ? "-o (the run file itself is continued)"
                : a->force           ? "--force (the run file itself is continued)"
                                     : "--summary/--dry-run/--print-defaults");
        return EXIT_USAGE;
    }
    install_handlers();
    /* immediate refusal when the run is still being written (its writer's lock) */
    if (cdem_runlock_check(a->resume_path, err) != CDEM_OK) {
        print_error(err->msg);
        return EXIT_ERROR;
    }
    cdem_run_options opt = {
        .output_path = a->resume_path,
        .params_text = NULL,
        .quiet = a->quiet,
        .progress_is_tty = isatty(STDERR_FILENO),
        .log = stderr,
        .stop_requested = &stop_requested,
        .max_steps = a->max_steps,
        .par_min = a->par_min,
        .no_fsync = a->no_fsync,
    };
    cdem_status st = cdem_run_resume(a->resume_path, &opt, err);
    if (st == CDEM_OK)
        return EXIT_OK;
    print_error(err->msg[0] ? err->msg : cdem_status_str(st));
    return st == CDEM_ERR_INTERRUPTED ? EXIT_INTERRUPTED : EXIT_ERROR;
}

/* --help, --version and the markdown tables: the texts that need no model. Returns 1 when
 * one of them was asked for (and printed), else 0. */
static int print_info(const cli_args *a) {
    if (a->help) {
        cdem_cli_help_print(stdout, &run_help);
        return 1;
    }
    if (a->version) {
        printf("cdem-run %s\n", CDEM_VERSION);
        return 1;
    }
    if (a->params_markdown) {
        cdem_params_write_markdown(stdout);
        return 1;
    }
    if (a->laws_markdown) {
        cdem_params_write_laws_markdown(stdout);
        return 1;
    }
    if (a->modes_markdown) {
        cdem_params_write_modes_markdown(stdout);
        return 1;
    }
    return 0;
}

/* The effective parameters into p: the defaults, the model file (or "-": standard input)
 * and the -s overrides in command-line order. *file_text gets the file's text (NULL without
 * a file; the caller frees it, also after a failure). */
static cdem_status load_params(const cli_args *a, cdem_params *p, char **file_text,
                               cdem_error *err) {
    cdem_params_defaults(p);
    if (a->model_path && !strcmp(a->model_path, "-")) {
        /* "-": the parameter file on standard input (generated or piped parameters) */
        CDEM_TRY(read_stdin(file_text, err));
        CDEM_TRY(cdem_params_parse_text(p, *file_text, "standard input", err));
    } else if (a->model_path) {
        CDEM_TRY(cdem_params_load(p, a->model_path, file_text, err));
    }
    for (int i = 0; i < a->n_overrides; i++)
        CDEM_TRY(cdem_params_override(p, a->overrides[i], err));
    return CDEM_OK;
}

/* The model summary on standard output, its element count that of the packing built here. */
static cdem_status print_summary(const cdem_params *p, const cdem_model *m, cdem_error *err) {
    long n_int = 0, n_wall = 0;
    int estimated = 0;
    cdem_error cerr;
    cdem_error_clear(&cerr);
    if (cdem_run_count_elements(p, &n_int, &n_wall, &cerr) != CDEM_OK) {
        /* The summary checks everything the run checks (issue 35, item 6: a missing,
         * folder or invalid fault file gave a summary and exit 0, then the run refused
         * it): an error of the inputs fails it as it would fail the run. Only the room
         * to build the packing here is not the run's problem: then the count is the
         * estimate. */
        if (cerr.code != CDEM_ERR_NOMEM) {
            *err = cerr;
            return cerr.code;
        }
        n_int = cdem_model_estimate_elements(p);
        n_wall = 0;
        estimated = 1;
    }
    char *summary = NULL;
    cdem_status st = cdem_summary_text(p, m, n_int, n_wall, estimated, &summary, err);
    if (st == CDEM_OK) {
        fputs(summary, stdout);
        fflush(stdout);
    }
    free(summary);
    return st;
}

/* Before the run (issue 46, item 8): an equilibration shorter than the assembly needs to come
 * to rest (the summary's rule of thumb, solver/run/estimate.h) is said now, not when the
 * equilibration ends (run.c warns then too, from the speeds it measures). */
static void warn_short_equilibration(const cdem_params *p, const cdem_model *m, int quiet) {
    const double need = cdem_estimate_equilibration_needed(m);
    if (quiet || !(p->equilibration < need))
        return;
    fprintf(stderr,
            "cdem-run: warning: time.equilibration = %g s is shorter than the about %.0f s an "
            "assembly %.0f average diameters tall needs to settle (the summary's rule of thumb): "
            "it will still be settling when the boundaries start to move; use "
            "time.equilibration = %.0f or more (docs/guide.md, section 4, \"Equilibration\")\n",
            p->equilibration, need, cdem_estimate_height_diameters(m), need);
}

/* Simulates p into out_path (NULL: no memory was left for its name). Takes file_text (the
 * model file's text, or NULL), which becomes the stored parameter text or is freed. Returns
 * the exit code; the messages are printed. */
static int simulate(const cli_args *a, const cdem_params *p, const char *out_path, char *file_text,
                    cdem_error *err) {
    char *params_text = stored_params_text(p, a, file_text);
    if (!out_path || !params_text) {
        free(params_text);
        fprintf(stderr, "cdem-run: out of memory\n");
        return EXIT_ERROR;
    }

    install_handlers();

    cdem_run_options opt = {
        .output_path = out_path,
        .params_text = params_text,
        .quiet = a->quiet,
        .progress_is_tty = isatty(STDERR_FILENO),
        .log = stderr,
        .stop_requested = &stop_requested,
        .max_steps = a->max_steps,
        .par_min = a->par_min,
        .ignore_free_space = a->ignore_free_space,
        .replace = a->force ? CDEM_H5_REPLACE_CDEM : CDEM_H5_REPLACE_NEVER,
        .no_fsync = a->no_fsync,
    };
    cdem_status st = cdem_run(p, &opt, err);
    free(params_text);
    if (st == CDEM_OK)
        return EXIT_OK;
    if (st == CDEM_ERR_INTERRUPTED) {
        print_error(err->msg[0] ? err->msg : "interrupted");
        return EXIT_INTERRUPTED;
    }
    print_error(err->msg);
    return EXIT_ERROR;
}

/* A model: its parameters, then --print-defaults, or the checks, the summary and (unless
 * --summary or --dry-run) the simulation. Returns the exit code; the messages are printed. */
static int run_model(const cli_args *a, cdem_error *err) {
    cdem_params p;
    char *file_text = NULL;
    char *out_path = NULL;
    int rc = EXIT_ERROR;

    if (load_params(a, &p, &file_text, err) != CDEM_OK)
        goto fail;
    if (a->print_defaults) {
        cdem_params_write(&p, stdout);
        rc = EXIT_OK;
        goto done;
    }
    if (cdem_run_validate(&p, err) != CDEM_OK) {
        fprintf(stderr, "cdem-run: %s%sthe parameters cannot be used as they are:\n",
                !a->model_path               ? ""
                : strcmp(a->model_path, "-") ? a->model_path
                                             : "standard input",
                a->model_path ? ": " : "");
        goto fail;
    }
    cdem_model m;
    if (cdem_bc_derive_model(&p, &m, err) != CDEM_OK || cdem_run_check_memory(&p, err) != CDEM_OK)
        goto fail;
    int running = !a->summary_only && !a->dry_run;
    if (running) {
        out_path = a->output_path ? strdup(a->output_path) : default_output(a->model_path);
        if (!out_path) {
            fprintf(stderr, "cdem-run: out of memory\n");
            goto done;
        }
        rc = check_output(a, &m, out_path, err);
        if (rc != EXIT_OK)
            goto done;
        rc = EXIT_ERROR;
    }

    int want_summary = a->summary_only || a->dry_run || !a->quiet;
    if (want_summary && print_summary(&p, &m, err) != CDEM_OK)
        goto fail;
    if (a->summary_only || a->dry_run) {
        if (a->dry_run)
            printf("\ndry run: nothing simulated\n");
        rc = EXIT_OK;
        goto done;
    }
    warn_short_equilibration(&p, &m, a->quiet);
    rc = simulate(a, &p, out_path, file_text, err);
    file_text = NULL; /* taken by simulate */
    goto done;

fail:
    print_error(err->msg);
    rc = EXIT_ERROR;
done:
    free(out_path);
    free(file_text);
    return rc;
}

int main(int argc, char **argv) {
    cdem_threads_settle_wait_policy(argv);
    cli_args a;
    memset(&a, 0, sizeof a);
    a.overrides = calloc((size_t)argc + 1, sizeof *a.overrides);
    if (!a.overrides) {
        fprintf(stderr, "cdem-run: out of memory\n");
        return EXIT_ERROR;
    }
    int rc = parse_args(argc, argv, &a);
    if (rc == EXIT_OK) {
#ifdef _OPENMP
        if (a.threads > 0)
            omp_set_num_threads(a.threads);
#endif
        cdem_error err;
        cdem_error_clear(&err);
        rc = print_info(&a) ? EXIT_OK : a.resume_path ? resume(&a, &err) : run_model(&a, &err);
    }
    free(a.overrides);
    return rc;
}
