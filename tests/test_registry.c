/* The registration tables of cdem-strain are complete (issue 20): every subcommand of the
 * command table (analysis/cli/commands.h) and every quantity of the quantity registry
 * (analysis/measure/quantity.h) is
 *   - documented: docs/analysis.md lists it (a command as `NAME` or "cdem-strain NAME", a
 *     quantity by its name), and
 *   - exercised: a test source under tests/ (other than this file) or a shell block of the
 *     pages whose examples tests/test_docs.c runs (README.md, docs/guide.md, docs/format.md)
 *     uses it: a command as the word after "cdem-strain" or as a quoted argument ("NAME" or
 *     "NAME ARGS..."), a quantity as a word of its own.
 * Adding a command or a quantity without its documentation and a test fails here, naming
 * it. The checker itself is tested on a corpus with a name left out. Runs from the
 * repository root. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "commands.h"
#include "quantity.h"

#include <ctype.h>
#include <glob.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scratch.h"

/* Appends text to the growing corpus *all (length *len). */
static void append(char **all, size_t *len, const char *text) {
    size_t n = strlen(text);
    char *grown = realloc(*all, *len + n + 2);
    assert_non_null(grown);
    memcpy(grown + *len, text, n);
    grown[*len + n] = '\n';
    grown[*len + n + 1] = '\0';
    *all = grown;
    *len += n + 1;
}

/* Appends the ```sh blocks of the page at path. */
static void append_sh_blocks(char **all, size_t *len, const char *path) {
    char *page = scratch_read_file(path);
    assert_non_null(page);
    for (char *s = strstr(page, "```sh\n"); s; s = strstr(s, "```sh\n")) {
        s += 6;
        char *e = strstr(s, "\n```");
        if (!e)
            break;
        *e = '\0';
        append(all, len, s);
        s = e + 1;
    }
    free(page);
}

/* The text in which the names must be exercised: the test sources and the run examples. */
static char *exercise_corpus(void) {
    char *all = NULL;
    size_t len = 0;
    append(&all, &len, "");
    static const char *const patterns[] = {"tests/*.c", "tests/*.h", "tests/*.sh",
                                           "tests/validate/*", "tests/docs/*.py"};
    for (size_t p = 0; p < sizeof patterns / sizeof patterns[0]; p++) {
        glob_t g;
        if (glob(patterns[p], 0, NULL, &g) != 0)
            continue;
        for (size_t i = 0; i < g.gl_pathc; i++) {
            if (strstr(g.gl_pathv[i], "test_registry.c"))
                continue; /* this file names nothing for real */
            char *text = scratch_read_file(g.gl_pathv[i]);
            if (text)
                append(&all, &len, text);
            free(text);
        }
        globfree(&g);
    }
    static const char *const pages[] = {"README.md", "docs/guide.md", "docs/format.md"};
    for (size_t p = 0; p < sizeof pages / sizeof pages[0]; p++)
        append_sh_blocks(&all, &len, pages[p]);
    return all;
}

static int name_char(char c) {
    return isalnum((unsigned char)c) || c == '-' || c == '_';
}

/* 1 when text holds name as a word of its own: not part of a longer name, not a member
 * (".name", "->name"). */
static int has_word(const char *text, const char *name) {
    const size_t n = strlen(name);
    for (const char *p = strstr(text, name); p; p = strstr(p + 1, name)) {
        const char before = p == text ? ' ' : p[-1];
        if (!name_char(before) && before != '.' && before != '>' && !name_char(p[n]))
            return 1;
    }
    return 0;
}

/* 1 when text uses the subcommand name: "cdem-strain NAME", or "NAME" / "NAME ..." as a
 * quoted argument. */
static int uses_command(const char *text, const char *name) {
    const size_t n = strlen(name);
    for (const char *p = strstr(text, name); p; p = strstr(p + 1, name)) {
        if (name_char(p[n]))
            continue;
        const int quoted = p > text && (p[-1] == '"' || p[-1] == '\'') &&
                           (p[n] == '"' || p[n] == '\'' || p[n] == ' ');
        const int after_program = p - text >= 12 && !strncmp(p - 12, "cdem-strain ", 12);
        if (quoted || after_program)
            return 1;
    }
    return 0;
}

/* 1 when the documentation page lists the subcommand. */
static int documents_command(const char *doc, const char *name) {
    char tick[64];
    snprintf(tick, sizeof tick, "`%s`", name);
    return strstr(doc, tick) || uses_command(doc, name);
}

/* Checks every name against the documentation doc and the exercise corpus; the missing
 * ones are appended to report ("NAME: not in docs/analysis.md"); returns their number. */
static int check_names(const char *const *names, size_t n, int commands, const char *doc,
                       const char *corpus, char *report, size_t cap) {
    int missing = 0;
    for (size_t i = 0; i < n; i++) {
        const int documented =
            commands ? documents_command(doc, names[i]) : has_word(doc, names[i]);
        const int exercised =
            commands ? uses_command(corpus, names[i]) : has_word(corpus, names[i]);
        if (!documented || !exercised) {
            size_t used = strlen(report);
            snprintf(report + used, cap - used, "  %s %s:%s%s\n", commands ? "command" : "quantity",
                     names[i], documented ? "" : " not listed in docs/analysis.md",
                     exercised ? "" : " used by no test nor documentation example");
            missing++;
        }
    }
    return missing;
}

static void test_registry_commands_documented_and_tested(void **state) {
    (void)state;
    char *doc = scratch_read_file("docs/analysis.md");
    assert_non_null(doc);
    char *corpus = exercise_corpus();
    size_t n;
    const cdem_command *const *rows = cdem_commands(&n);
    assert_true(n > 10);
    const char **names = calloc(n, sizeof *names);
    assert_non_null(names);
    for (size_t i = 0; i < n; i++) {
        names[i] = rows[i]->name;
        /* a row is complete: its help, its summary and its handler */
        assert_non_null(rows[i]->summary);
        assert_non_null(rows[i]->help);
        assert_non_null(rows[i]->run);
        assert_ptr_equal(cdem_command_find(names[i]), rows[i]);
    }
    char report[8192] = "";
    if (check_names(names, n, 1, doc, corpus, report, sizeof report))
        fail_msg("subcommands of cdem-strain without documentation or test:\n%s", report);
    free(names);
    free(corpus);
    free(doc);
}

static void test_registry_quantities_documented_and_tested(void **state) {
    (void)state;
    char *doc = scratch_read_file("docs/analysis.md");
    assert_non_null(doc);
    char *corpus = exercise_corpus();
    size_t n;
    const cdem_quantity *table = cdem_quantity_table(&n);
    assert_true(n > 10);
    const char **names = calloc(n, sizeof *names);
    assert_non_null(names);
    for (size_t i = 0; i < n; i++)
        names[i] = table[i].name;
    char report[8192] = "";
    if (check_names(names, n, 0, doc, corpus, report, sizeof report))
        fail_msg("quantities without documentation or test:\n%s", report);
    free(names);
    free(corpus);
    free(doc);
}

/* The checker finds a name left out of the documentation or of the tests. */
static void test_registry_checker_reports_missing_names(void **state) {
    (void)state;
    static const char *const commands[] = {"series", "plot-series", "help"};
    const char *doc = "| `series` | the time series |\n| `plot-series` | a plot |\n";
    const char *corpus = "run(c, \"cdem-strain\", \"series run.h5\");\n"
                         "cdem-strain plot-series run.h5 --y time -o p.png\n"
                         "printf(\"see the help\");\n";
    char report[1024] = "";
    assert_int_equal(check_names(commands, 3, 1, doc, corpus, report, sizeof report), 1);
    assert_non_null(strstr(report, "command help: not listed in docs/analysis.md used by no"));
    static const char *const quantities[] = {"total-e1", "sxx", "cum-e3"};
    const char *qdoc = "| total-e1, sxx | |\n| cum-e3 | |\n";
    const char *qcorpus = "--quantity total-e1\n s->sxx = 1;\n \"cum-e3\" \"sxx\"\n";
    report[0] = '\0';
    assert_int_equal(check_names(quantities, 3, 0, qdoc, qcorpus, report, sizeof report), 0);
    /* "total-e1" inside "total-e12" and a member ".sxx" do not count */
    const char *thin = "total-e12 p.sxx cum-e3\n";
    assert_int_equal(check_names(quantities, 3, 0, qdoc, thin, report, sizeof report), 2);
    assert_non_null(strstr(report, "quantity sxx:"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registry_commands_documented_and_tested),
        cmocka_unit_test(test_registry_quantities_documented_and_tested),
        cmocka_unit_test(test_registry_checker_reports_missing_names),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
