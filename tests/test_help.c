/* Tests of the help of both programs and of every cdem-strain subcommand, run as programs
 * (issue 18): -h and --help print to stdout and exit 0, in one layout (common/cli_help.h);
 * `cdem-strain help CMD` prints the same text as `cdem-strain CMD --help`; every option a
 * help lists is in its usage forms and is accepted by the command's parser; an unknown
 * option is a usage error that points to the command's help; -V prints the version.
 * The subcommands are taken from `cdem-strain --help` itself, so a new command is walked
 * without editing this test. Programs in $CDEM_BUILD (default build/); scratch files in
 * $CDEM_TEST_TMP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "scratch.h"

#define OUT_MAX (1 << 18)

/* snprintf into an array, failing the test when the text does not fit */
#define FMT(buf, ...) assert_true(snprintf(buf, sizeof buf, __VA_ARGS__) < (int)sizeof buf)

typedef struct {
    char build[1024];    /* directory of cdem-run and cdem-strain */
    scratch_dir scratch; /* private scratch directory */
    char out[OUT_MAX], err[OUT_MAX];
} help_ctx;

static int setup(void **state) {
    help_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    snprintf(c->build, sizeof c->build, "%s", b && b[0] ? b : "build");
    if (scratch_dir_make(&c->scratch, "test_help") != 0) {
        free(c);
        return -1;
    }
    *state = c;
    return 0;
}

static int teardown(void **state) {
    help_ctx *c = *state;
    int rc = scratch_dir_remove(&c->scratch);
    free(c);
    return rc;
}

static void slurp(const char *path, char *buf) {
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t n = fread(buf, 1, OUT_MAX - 1, f);
    buf[n] = '\0';
    fclose(f);
}

/* Runs PROGRAM ARGS (shell syntax) in the scratch directory; c->out and c->err get its
 * output; returns the exit status. */
static int run(help_ctx *c, const char *program, const char *args) {
    char cmd[4096], o[1100], e[1100];
    FMT(o, "%s/out.txt", c->scratch.dir);
    FMT(e, "%s/err.txt", c->scratch.dir);
    char bin[1100];
    FMT(bin, "%s/%s", c->build, program);
    if (bin[0] != '/') {
        char cwd[1024];
        assert_non_null(getcwd(cwd, sizeof cwd));
        FMT(bin, "%s/%s/%s", cwd, c->build, program);
    }
    if (access(bin, X_OK) != 0)
        fail_msg("%s is missing: build it first (make)", bin);
    FMT(cmd, "cd '%s' && '%s' %s >'%s' 2>'%s' </dev/null", c->scratch.dir, bin, args, o, e);
    int st = system(cmd);
    assert_true(WIFEXITED(st));
    slurp(o, c->out);
    slurp(e, c->err);
    return WEXITSTATUS(st);
}

/* The text of the section under `heading` ("Options:") up to the next blank line. */
static char *section(const char *help, const char *heading, char *buf, size_t cap) {
    char key[64];
    FMT(key, "\n%s\n", heading);
    const char *s = strstr(help, key);
    buf[0] = '\0';
    if (!s)
        return NULL;
    s += strlen(key);
    const char *e = strstr(s, "\n\n");
    size_t n = e ? (size_t)(e - s) + 1 : strlen(s);
    if (n >= cap)
        n = cap - 1;
    memcpy(buf, s, n);
    buf[n] = '\0';
    return buf;
}

/* The usage forms: the first block of the help. */
static void usage_block(const char *help, char *buf, size_t cap) {
    const char *e = strstr(help, "\n\n");
    size_t n = e ? (size_t)(e - help) : strlen(help);
    if (n >= cap)
        n = cap - 1;
    memcpy(buf, help, n);
    buf[n] = '\0';
}

/* Checks the common layout of a help text of `program` ("cdem-strain render"). */
static void check_layout(const char *help, const char *program) {
    char want[256];
    FMT(want, "usage: %s", program);
    if (strncmp(help, want, strlen(want)) != 0)
        fail_msg("help of %s does not start with '%s':\n%.300s", program, want, help);
    if (!strstr(help, "\nOptions:\n"))
        fail_msg("help of %s has no Options: section", program);
    if (!strstr(help, "\n  -h, --help           print this help and exit\n"))
        fail_msg("help of %s does not list -h, --help", program);
    const char *last = strstr(help, "\nExit status: ");
    if (!last || strstr(last, "\n\n") || help[strlen(help) - 1] != '\n')
        fail_msg("help of %s does not end with its Exit status paragraph", program);
    /* no line wider than the layout's 80 columns */
    for (const char *s = help; *s;) {
        size_t n = strcspn(s, "\n");
        if (n > 80)
            fail_msg("help of %s has a line of %zu columns: %.*s", program, n, (int)n, s);
        s += n + (s[n] == '\n');
    }
}

/* For each row "  -x, --name ARG   text" of the options section: calls fn with the first
 * spelling and whether the option takes a value (an ARG follows the names). */
typedef void (*option_fn)(help_ctx *c, const char *program, const char *cmd, const char *name,
                          int takes_value, const char *usage);

static void each_option(help_ctx *c, const char *program, const char *cmd, const char *help,
                        option_fn fn) {
    char opts[16384], usage[8192];
    assert_non_null(section(help, "Options:", opts, sizeof opts));
    usage_block(help, usage, sizeof usage);
    for (char *line = strtok(opts, "\n"); line; line = strtok(NULL, "\n")) {
        if (strncmp(line, "  -", 3) != 0)
            continue; /* a continuation line */
        char names[256];
        size_t n = strcspn(line + 2, " ,");
        FMT(names, "%.*s", (int)n, line + 2);
        if (!strcmp(names, "-h"))
            continue;
        /* the spellings end at two spaces (then the text) or at a word not starting '-' */
        const char *p = line + 2;
        int takes_value = 0;
        while (*p && strncmp(p, "  ", 2) != 0) {
            while (*p == ' ' || *p == ',')
                p++;
            if (*p && *p != '-') {
                takes_value = 1;
                break;
            }
            p += strcspn(p, " ,");
        }
        fn(c, program, cmd, names, takes_value, usage);
    }
}

/* The option is in the usage forms as a whole word. */
static void option_in_usage(help_ctx *c, const char *program, const char *cmd, const char *name,
                            int takes_value, const char *usage) {
    (void)c;
    (void)takes_value;
    const char *s = usage;
    size_t n = strlen(name);
    while ((s = strstr(s, name)) != NULL) {
        char before = s == usage ? ' ' : s[-1], after = s[n];
        if (strchr(" [|", before) && strchr(" ]|\n", after ? after : '\n'))
            return;
        s += n;
    }
    fail_msg("%s%s%s: option %s is in the help but not in its usage forms:\n%s", program,
             cmd ? " " : "", cmd ? cmd : "", name, usage);
}

/* The command's parser knows the option: given alone (with a value when it takes one) it
 * may fail for other reasons (no run file) but never as an unknown option. */
static void option_accepted(help_ctx *c, const char *program, const char *cmd, const char *name,
                            int takes_value, const char *usage) {
    (void)usage;
    char args[512];
    /* cdem-run: --version after the option stops after parsing, before any work */
    FMT(args, "%s %s %s %s", cmd ? cmd : "", name, takes_value ? "1" : "", cmd ? "" : "--version");
    int rc = run(c, program, args);
    if (strstr(c->err, "unknown option") || strstr(c->err, "unknown command"))
        fail_msg("'%s %s' (exit %d): the parser does not know an option its help lists: %s",
                 program, args, rc, c->err);
    if (!cmd)
        assert_int_equal(rc, 0);
}

static void test_help_cdem_run(void **state) {
    help_ctx *c = *state;
    assert_int_equal(run(c, "cdem-run", "--help"), 0);
    assert_string_equal(c->err, "");
    check_layout(c->out, "cdem-run");
    char help[OUT_MAX];
    FMT(help, "%s", c->out);
    assert_int_equal(run(c, "cdem-run", "-h"), 0);
    assert_string_equal(c->out, help);
    /* the options the issue found missing from the synopsis, and -V */
    char usage[8192];
    usage_block(help, usage, sizeof usage);
    assert_non_null(strstr(usage, "[--par-min N]"));
    each_option(c, "cdem-run", NULL, help, option_in_usage);
    each_option(c, "cdem-run", NULL, help, option_accepted);
    assert_int_equal(run(c, "cdem-run", "-V"), 0);
    assert_non_null(strstr(c->out, "cdem-run "));
    char version[256];
    FMT(version, "%s", c->out);
    assert_int_equal(run(c, "cdem-run", "--version"), 0);
    assert_string_equal(c->out, version);
    /* an unknown option points to the help */
    assert_int_equal(run(c, "cdem-run", "--no-such-option"), 2);
    assert_non_null(strstr(c->err, "unknown option --no-such-option"));
    assert_non_null(strstr(c->err, "Try 'cdem-run --help'"));
}

/* The subcommand names of the general help's Commands: section. */
static size_t commands(const char *help, char names[][32], size_t cap) {
    char list[8192];
    assert_non_null(section(help, "Commands:", list, sizeof list));
    size_t n = 0;
    for (char *line = strtok(list, "\n"); line && n < cap; line = strtok(NULL, "\n"))
        if (line[0] == ' ' && line[1] == ' ' && line[2] != ' ')
            snprintf(names[n++], 32, "%.*s", (int)strcspn(line + 2, " "), line + 2);
    return n;
}

static void test_help_cdem_strain_and_every_subcommand(void **state) {
    help_ctx *c = *state;
    assert_int_equal(run(c, "cdem-strain", "--help"), 0);
    assert_string_equal(c->err, "");
    check_layout(c->out, "cdem-strain");
    char general[OUT_MAX];
    FMT(general, "%s", c->out);
    assert_int_equal(run(c, "cdem-strain", "-h"), 0);
    assert_string_equal(c->out, general);
    assert_int_equal(run(c, "cdem-strain", "help"), 0);
    assert_string_equal(c->out, general);
    assert_int_equal(run(c, "cdem-strain", "-V"), 0);
    assert_non_null(strstr(c->out, "cdem-strain "));

    char names[64][32];
    size_t n = commands(general, names, 64);
    /* the 14 subcommands of the issue are all there (and any added later) */
    const char *known[] = {"info",          "compute",     "element",     "limits",
                           "render",        "plot-series", "mohr",        "repose",
                           "wedge",         "plot-csv",    "export-sspx", "export-biaxial",
                           "import-cdem2d", "quantities"};
    for (size_t k = 0; k < sizeof known / sizeof known[0]; k++) {
        size_t j = 0;
        while (j < n && strcmp(names[j], known[k]) != 0)
            j++;
        if (j == n)
            fail_msg("cdem-strain --help does not list the command %s", known[k]);
    }
    for (size_t k = 0; k < n; k++) {
        char program[64], args[256], help[OUT_MAX];
        FMT(program, "cdem-strain %s", names[k]);
        FMT(args, "%s --help", names[k]);
        if (run(c, "cdem-strain", args) != 0 || c->err[0])
            fail_msg("'%s --help' failed or wrote to stderr: %s", program, c->err);
        check_layout(c->out, program);
        FMT(help, "%s", c->out);
        /* -h, `help CMD` and --help after other arguments print the same */
        FMT(args, "%s -h", names[k]);
        assert_int_equal(run(c, "cdem-strain", args), 0);
        assert_string_equal(c->out, help);
        FMT(args, "help %s", names[k]);
        assert_int_equal(run(c, "cdem-strain", args), 0);
        assert_string_equal(c->out, help);
        FMT(args, "%s run.h5 --help", names[k]);
        assert_int_equal(run(c, "cdem-strain", args), 0);
        assert_string_equal(c->out, help);
        each_option(c, "cdem-strain", names[k], help, option_in_usage);
        each_option(c, "cdem-strain", names[k], help, option_accepted);
        /* an unknown option: usage error naming it, pointing to this command's help */
        if (strcmp(names[k], "help") != 0) {
            FMT(args, "%s --no-such-option", names[k]);
            assert_int_equal(run(c, "cdem-strain", args), 2);
            char want[128];
            FMT(want, "Try 'cdem-strain %s --help'", names[k]);
            if (!strstr(c->err, "unknown option '--no-such-option'") || !strstr(c->err, want))
                fail_msg("'%s --no-such-option' printed: %s", program, c->err);
            assert_string_equal(c->out, "");
        }
    }
    /* help of an unknown command, and no command at all: usage errors */
    assert_int_equal(run(c, "cdem-strain", "help no-such-command"), 2);
    assert_non_null(strstr(c->err, "unknown command 'no-such-command'"));
    assert_int_equal(run(c, "cdem-strain", ""), 2);
    assert_non_null(strstr(c->err, "Try 'cdem-strain --help'"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_help_cdem_run, setup, teardown),
        cmocka_unit_test_setup_teardown(test_help_cdem_strain_and_every_subcommand, setup,
                                        teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
