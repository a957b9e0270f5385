/* Tests of the generated docs: the man pages man/cdem-run.1 and man/cdem-strain.1 and the
 * bash completion, generated from the programs' --help text (scripts/help2roff.py and
 * help2completion.py: `make man completion`), and docs/errors.md, generated from the
 * sources (scripts/error_catalogue.py: `make errors`); none may go stale.
 * Runs from the repository root (tests/run_tests.sh); programs in $CDEM_BUILD (default
 * build/); scratch files in $CDEM_TEST_TMP. */
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

typedef struct {
    char build[1024];    /* directory of cdem-run and cdem-strain */
    scratch_dir scratch; /* private scratch directory */
} man_ctx;

static int setup(void **state) {
    man_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    snprintf(c->build, sizeof c->build, "%s", b && b[0] ? b : "build");
    if (scratch_dir_make(&c->scratch, "test_man") != 0) {
        free(c);
        return -1;
    }
    *state = c;
    return 0;
}

static int teardown(void **state) {
    man_ctx *c = *state;
    if (scratch_dir_remove(&c->scratch) != 0)
        fprintf(stderr, "test_man: could not remove %s\n", c->scratch.dir);
    free(c);
    return 0;
}

/* Reads a whole file into a NUL-terminated buffer (caller frees); NULL when unreadable. */
static char *slurp(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + n, 1, cap - n - 1, f)) > 0) {
        n += got;
        if (n + 1 == cap) {
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb;
            cap *= 2;
        }
    }
    fclose(f);
    if (buf)
        buf[n] = '\0';
    return buf;
}

/* Runs a shell command; returns its exit status (-1 when it did not exit normally). */
static int run(const char *cmd) {
    int rc = system(cmd);
    return (rc != -1 && WIFEXITED(rc)) ? WEXITSTATUS(rc) : -1;
}

/* Generates the pages into DIR; returns the generator's exit status. */
static int generate(const man_ctx *c, const char *dir) {
    char cmd[4200];
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 scripts/help2roff.py '%s' '%s' 2>&1", c->build,
             dir);
    return run(cmd);
}

/* NULL when the committed page equals the generated one, else a message naming the page. */
static const char *compare_page(const char *committed, const char *generated, char *msg,
                                size_t cap) {
    char *a = slurp(committed), *b = slurp(generated);
    const char *res = NULL;
    if (!a || !b)
        snprintf(msg, cap, "%s or %s cannot be read", committed, generated), res = msg;
    else if (strcmp(a, b) != 0)
        snprintf(msg, cap, "%s is stale against --help: run `make man` and commit it", committed),
            res = msg;
    free(a);
    free(b);
    return res;
}

static void test_man_pages_match_help(void **state) {
    man_ctx *c = *state;
    assert_int_equal(generate(c, c->scratch.dir), 0);
    const char *pages[] = {"cdem-run.1", "cdem-strain.1"};
    for (size_t i = 0; i < 2; i++) {
        char committed[256], generated[2100], msg[2400];
        snprintf(committed, sizeof committed, "man/%s", pages[i]);
        snprintf(generated, sizeof generated, "%s/%s", c->scratch.dir, pages[i]);
        const char *err = compare_page(committed, generated, msg, sizeof msg);
        if (err)
            fail_msg("%s", err);
    }
}

/* Every long option of cdem-run --help and every cdem-strain command is in the pages. */
static void test_man_lists_every_option_and_command(void **state) {
    man_ctx *c = *state;
    char *run_page = slurp("man/cdem-run.1"), *strain_page = slurp("man/cdem-strain.1");
    assert_non_null(run_page);
    assert_non_null(strain_page);
    const char *options[] = {"\\-o OUT.h5",
                             "\\-s section.key=value",
                             "\\-\\-summary",
                             "\\-\\-dry\\-run",
                             "\\-\\-print\\-defaults",
                             "\\-\\-params\\-markdown",
                             "\\-\\-max\\-steps N",
                             "\\-\\-version",
                             "\\-\\-par\\-min N",
                             "\\-V"};
    for (size_t i = 0; i < sizeof options / sizeof options[0]; i++)
        if (!strstr(run_page, options[i]))
            fail_msg("man/cdem-run.1 lacks option %s", options[i]);
    const char *commands[] = {"info",
                              "compute",
                              "element",
                              "limits",
                              "export\\-sspx",
                              "export\\-biaxial",
                              "import\\-cdem2d",
                              "quantities",
                              "render",
                              "plot\\-series",
                              "mohr",
                              "repose",
                              "wedge",
                              "plot\\-csv",
                              "help"};
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++) {
        char row[128];
        snprintf(row, sizeof row, ".TP\n\\fB%s\\fR\n", commands[i]);
        if (!strstr(strain_page, row))
            fail_msg("man/cdem-strain.1 lacks command %s", commands[i]);
        /* and a subsection with the command's own usage and options */
        snprintf(row, sizeof row, ".SS %s\n.nf\ncdem\\-strain %s", commands[i], commands[i]);
        if (!strstr(strain_page, row))
            fail_msg("man/cdem-strain.1 lacks the usage of command %s", commands[i]);
    }
    /* the render options come from `cdem-strain render --help` */
    assert_non_null(strstr(strain_page, "\\-\\-above\\-tenth\\-max"));
    assert_non_null(strstr(run_page, ".SH EXIT STATUS\n0 completed, 1 error, 2 usage error"));
    free(run_page);
    free(strain_page);
    (void)c;
}

/* A page that differs from the generated one is reported as stale, naming it. */
static void test_man_detects_a_stale_page(void **state) {
    man_ctx *c = *state;
    assert_int_equal(generate(c, c->scratch.dir), 0);
    char page[2100], copy[2100], cmd[4400], msg[2400];
    snprintf(page, sizeof page, "%s/cdem-run.1", c->scratch.dir);
    snprintf(copy, sizeof copy, "%s/stale-cdem-run.1", c->scratch.dir);
    snprintf(cmd, sizeof cmd, "sed 's/print the version and exit/print the version/' '%s' > '%s'",
             page, copy);
    assert_int_equal(run(cmd), 0);
    const char *err = compare_page(copy, page, msg, sizeof msg);
    assert_non_null(err);
    assert_non_null(strstr(err, "stale-cdem-run.1 is stale against --help: run `make man`"));
    assert_null(compare_page(page, page, msg, sizeof msg));
}

/* The bash completion is generated from the same help texts (make completion) and must not
 * be stale; and it completes: command words, a command's options, quantity names after
 * --color, the words of a choice list, cdem-run's options (issue 18: generated from the
 * option tables) and the section.key= words after cdem-run -s. */
static void test_man_completion_fresh_and_working(void **state) {
    man_ctx *c = *state;
    char cmd[4400], generated[2100], msg[2400];
    snprintf(generated, sizeof generated, "%s/cdem-c.bash", c->scratch.dir);
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 scripts/help2completion.py '%s' '%s' 2>&1",
             c->build, generated);
    assert_int_equal(run(cmd), 0);
    const char *err = compare_page("completion/cdem-c.bash", generated, msg, sizeof msg);
    if (err)
        fail_msg("%s (run `make completion`)", err);
    static const struct {
        const char *words; /* COMP_WORDS, the last one being completed */
        const char *want;  /* what COMPREPLY must hold, space-separated (NULL: only the
                              program's own option spellings, checked below) */
    } cases[] = {
        {"cdem-strain ren", "render"},
        {"cdem-strain render run.h5 --col", "--color --colour --colour-bar-space --color-bar-space "
                                            "--color-walls --colour-walls "
                                            "--color-layers --colour-layers"},
        {"cdem-strain render run.h5 --color total-max-s", "total-max-shear"},
        {"cdem-strain render run.h5 --vectors ''", "incr total"},
        {"cdem-strain compute run.h5 --format ''", "csv h5"},
        {"cdem-strain help plot", "plot-series plot-csv"},
        {"cdem-strain info run.h5 --j", "--json"},
        {"cdem-run --par", "--params-markdown --par-min"},
        /* -s: every key of --print-defaults as section.key= (issue 46, item 13b: nothing) */
        {"cdem-run model.ini -s physics.grav", "physics.gravity="},
        {"cdem-run -s assembly.half", "assembly.half_radii="},
        /* a choice list whose words hold hyphens: whole words, and no "-strain" option */
        {"cdem-strain render run.h5 --axes ''", "incr-strain total-strain stress"},
        {"cdem-strain render run.h5 -", NULL},
        {"cdem-strain export-sspx run.h5 -", NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char out[2048];
        snprintf(out, sizeof out, "%s/reply.txt", c->scratch.dir);
        snprintf(cmd, sizeof cmd,
                 "bash -c 'source completion/cdem-c.bash; COMP_WORDS=(%s); "
                 "COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); "
                 "case ${COMP_WORDS[0]} in cdem-run) _cdem_run;; *) _cdem_strain;; esac; "
                 "echo \"${COMPREPLY[*]}\"' > '%s'",
                 cases[i].words, out);
        /* the words go through the shell: '' stands for an empty word */
        char *quoted = strstr(cmd, "''");
        if (quoted)
            memcpy(quoted, "\"\"", 2);
        assert_int_equal(run(cmd), 0);
        char *reply = slurp(out);
        assert_non_null(reply);
        reply[strcspn(reply, "\n")] = '\0';
        if (!cases[i].want) {
            /* every option offered is a word of the help's option spellings: none starts
             * inside a value (`-strain` of `incr-strain`, `-B` of `A-B`) */
            for (char *w = strtok(reply, " "); w; w = strtok(NULL, " "))
                if (w[0] == '-' && w[1] != '-' && strlen(w) > 2)
                    fail_msg("completing '%s' offered '%s', not an option", cases[i].words, w);
        } else if (strcmp(reply, cases[i].want) != 0) {
            fail_msg("completing '%s' gave '%s', expected '%s'", cases[i].words, reply,
                     cases[i].want);
        }
        free(reply);
    }
}

/* docs/errors.md is generated from the sources' messages (with their file:line) by
 * scripts/error_catalogue.py and must not go stale: a changed message, or code moved
 * above one, makes it differ (test_error_catalogue checks that the script misses none). */
static void test_man_error_catalogue_fresh(void **state) {
    man_ctx *c = *state;
    char cmd[2400], generated[2100], msg[2400];
    snprintf(generated, sizeof generated, "%s/errors.md", c->scratch.dir);
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 scripts/error_catalogue.py > '%s'", generated);
    assert_int_equal(run(cmd), 0);
    char *a = slurp("docs/errors.md"), *b = slurp(generated);
    assert_non_null(a);
    assert_non_null(b);
    if (strcmp(a, b) != 0)
        snprintf(msg, sizeof msg,
                 "docs/errors.md is stale against the sources: run `make errors` and "
                 "commit it");
    else
        msg[0] = '\0';
    free(a);
    free(b);
    if (msg[0])
        fail_msg("%s", msg);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_man_completion_fresh_and_working, setup, teardown),
        cmocka_unit_test_setup_teardown(test_man_error_catalogue_fresh, setup, teardown),
        cmocka_unit_test_setup_teardown(test_man_pages_match_help, setup, teardown),
        cmocka_unit_test_setup_teardown(test_man_lists_every_option_and_command, setup, teardown),
        cmocka_unit_test_setup_teardown(test_man_detects_a_stale_page, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
