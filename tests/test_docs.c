/* The documentation's code runs (issue 18): every ```sh, ```python and ```make block of
 * README.md, docs/guide.md and docs/format.md is executed by tests/docs/run_doc_blocks.py
 * (long simulations only as quick checks here; all of them in make validate), and blocks
 * that cannot run carry a marker with the reason. The runner itself is checked on a page
 * with the h5py example the issue found broken (the version-1 layout: KeyError).
 * Runs from the repository root; programs in $CDEM_BUILD; scratch in $CDEM_TEST_TMP. */
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

/* Runs the block runner with args; its output into out; returns its exit status. */
static int run_blocks(const char *args, char *out, size_t cap) {
    const char *b = getenv("CDEM_BUILD");
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 tests/docs/run_doc_blocks.py '%s' %s 2>&1",
             b && b[0] ? b : "build", args);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, cap - 1, p);
    out[n] = '\0';
    char sink[4096];
    while (fread(sink, 1, sizeof sink, p) > 0) {
    }
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void test_docs_blocks_run(void **state) {
    (void)state;
    static char out[1 << 16];
    int rc = run_blocks("", out, sizeof out);
    printf("%s", out);
    if (rc != 0)
        fail_msg("a documentation block failed (output above)");
    assert_non_null(strstr(out, " 0 failed"));
    /* the pages' code is there to be run: at least the h5py examples and the import */
    assert_non_null(strstr(out, "docs/guide.md:"));
    assert_non_null(strstr(out, "docs/format.md:"));
    assert_null(strstr(out, "doc blocks: 0 ran"));
}

/* The runner fails on the broken example, names the page and line, and refuses a skip
 * without a reason. */
static void test_docs_runner_catches_the_old_example(void **state) {
    (void)state;
    char page[1024], args[1200];
    scratch_path(page, sizeof page, "test_docs_page.md");
    FILE *f = fopen(page, "w");
    assert_non_null(f);
    fputs("# page\n\n<!-- doc-test\nsetup: cp \"$DOCTEST_RUN\" run.h5\n-->\n```python\n"
          "import h5py\nf = h5py.File(\"run.h5\", \"r\")\nf[\"increments/000282/x\"][:]\n```\n",
          f);
    fclose(f);
    static char out[1 << 16];
    snprintf(args, sizeof args, "'%s'", page);
    assert_int_equal(run_blocks(args, out, sizeof out), 1);
    assert_non_null(strstr(out, ":6 (python): FAILED"));
    assert_non_null(strstr(out, "KeyError"));
    f = fopen(page, "w");
    assert_non_null(f);
    fputs("<!-- doc-test\nmode: skip\n-->\n```sh\ntrue\n```\n", f);
    fclose(f);
    assert_int_not_equal(run_blocks(args, out, sizeof out), 0);
    assert_non_null(strstr(out, "doc-test mode skip needs a (reason)"));
    remove(page);
}

/* Appends to report every command of a ```sh or ```make block of path that calls cdem-run or
 * cdem-strain without build/; returns how many. */
static int bare_program_calls(const char *path, char *report, size_t cap) {
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[4096];
    int in_block = 0, n = 0, lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        if (!strncmp(line, "```", 3)) {
            in_block = in_block ? 0 : (!strncmp(line, "```sh", 5) || !strncmp(line, "```make", 7));
            continue;
        }
        if (!in_block)
            continue;
        char *hash = strstr(line, " #");
        if (hash)
            *hash = '\0';
        if (line[0] == '#')
            continue;
        /* a command starts the line or follows &&, ||, ;, |, $( or ( */
        int at_command = 1;
        for (char *tok = strtok(line, " \t\n"); tok; tok = strtok(NULL, " \t\n")) {
            while (*tok == '(' || (tok[0] == '$' && tok[1] == '('))
                tok += *tok == '$' ? 2 : 1;
            if (at_command && (!strcmp(tok, "cdem-run") || !strcmp(tok, "cdem-strain"))) {
                const size_t o = strlen(report);
                snprintf(report + o, cap - o, "\n  %s:%d: %s", path, lineno, tok);
                n++;
            }
            at_command = !strcmp(tok, "&&") || !strcmp(tok, "||") || !strcmp(tok, ";") ||
                         !strcmp(tok, "|") || !strcmp(tok, "then") || !strcmp(tok, "do");
        }
    }
    fclose(f);
    return n;
}

/* The guide and the README run the programs as build/cdem-run and build/cdem-strain, which
 * work right after `make`, and say once that an installed copy drops the build/ (issue 35:
 * the guide's cdem2D import block called bare cdem-strain, which needs `make install`; the
 * block runner puts the programs on PATH, so running the blocks could not tell). */
static void test_docs_blocks_call_the_built_programs(void **state) {
    (void)state;
    static char report[8192];
    report[0] = '\0';
    int n = bare_program_calls("README.md", report, sizeof report) +
            bare_program_calls("docs/guide.md", report, sizeof report);
    if (n)
        fail_msg("%d commands call the programs without build/:%s", n, report);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_docs_blocks_call_the_built_programs),
        cmocka_unit_test(test_docs_blocks_run),
        cmocka_unit_test(test_docs_runner_catches_the_old_example),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
