/* Tests of common/cli_help: the help layout (80 columns, option text in column 23, usage
 * forms never broken inside [...], later forms and continuations indented), option lookup
 * (every spelling, --opt=value, a switch refusing a value), -h/--help detection that skips
 * option values, the usage-error text, and the nearest spelling of an unknown option. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cli_help.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const forms[] = {
    "RUN.h5 [--alpha A] [--beta B] [--gamma-with-a-long-name VALUE] [--delta D] "
    "[--epsilon-also-long E] [--zeta Z]",
    "RUN.h5 --second", NULL};
static const cdem_cli_option options[] = {
    {"-o, --output", "OUT", "output file"},
    {"--flag", NULL, "a switch"},
    {"--a-very-long-option-name", "VALUE",
     "an option whose name is longer than the column, so its text starts on the next line "
     "and wraps at eighty columns like every other text"},
    {NULL, NULL, NULL}};
static const cdem_cli_help help = {
    .program = "prog sub",
    .forms = forms,
    .about = "First paragraph.\n\n  an example kept as it is",
    .options = options,
    .notes = "A note.",
};

static char *printed(void (*fn)(FILE *, const cdem_cli_help *, const char *), const char *what) {
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    if (fn)
        fn(f, &help, what);
    else
        cdem_cli_help_print(f, &help);
    fclose(f);
    return buf;
}

static void test_cli_help_layout(void **state) {
    (void)state;
    char *t = printed(NULL, NULL);
    assert_true(strncmp(t, "usage: prog sub RUN.h5 [--alpha A]", 34) == 0);
    for (const char *s = t; *s;) { /* 80 columns; no [...] split over two lines */
        size_t n = strcspn(s, "\n");
        assert_true(n <= CDEM_CLI_HELP_WIDTH);
        int depth = 0;
        for (size_t i = 0; i < n; i++)
            depth += (s[i] == '[') - (s[i] == ']');
        assert_int_equal(depth, 0);
        s += n + (s[n] == '\n');
    }
    /* continuation of the first form under its first argument; the second form */
    assert_non_null(strstr(t, "\n                [--"));
    assert_non_null(strstr(t, "\n       prog sub RUN.h5 --second\n"));
    assert_non_null(strstr(t, "\n\nFirst paragraph.\n\n  an example kept as it is\n"));
    assert_non_null(strstr(t, "\nOptions:\n  -o, --output OUT     output file\n"));
    assert_non_null(strstr(t, "\n  --flag               a switch\n"));
    assert_non_null(strstr(t, "\n  --a-very-long-option-name VALUE\n                       an"));
    assert_non_null(strstr(t, "\n  -h, --help           print this help and exit\n"));
    assert_non_null(strstr(t, "\n\nA note.\n\nExit status: 0 success, 1 error, 2 usage error.\n"));
    free(t);
}

static void test_cli_help_find_option(void **state) {
    (void)state;
    const char *v = "x";
    assert_ptr_equal(cdem_cli_find_option(&help, "-o", &v), &options[0]);
    assert_null(v);
    assert_ptr_equal(cdem_cli_find_option(&help, "--output=a.csv", &v), &options[0]);
    assert_string_equal(v, "a.csv");
    assert_ptr_equal(cdem_cli_find_option(&help, "--flag", &v), &options[1]);
    assert_null(cdem_cli_find_option(&help, "--flag=1", &v)); /* a switch takes no value */
    assert_null(cdem_cli_find_option(&help, "--out", &v));    /* no abbreviations */
    assert_null(cdem_cli_find_option(&help, "-h", &v));       /* help is not in the table */
    assert_true(cdem_cli_option_is(&options[0], "--output"));
    assert_false(cdem_cli_option_is(&options[0], "--outpu"));
}

static void test_cli_help_wants_help(void **state) {
    (void)state;
    char *a1[] = {"prog", "sub", "run.h5", "--help"};
    assert_int_equal(cdem_cli_wants_help(4, a1, 2, &help), 3);
    char *a2[] = {"prog", "sub", "-o", "-h"}; /* -h is the value of -o */
    assert_int_equal(cdem_cli_wants_help(4, a2, 2, &help), 0);
    char *a3[] = {"prog", "sub", "--output=-h", "-h"};
    assert_int_equal(cdem_cli_wants_help(4, a3, 2, &help), 3);
    char *a4[] = {"prog", "sub", "--flag", "-h"};
    assert_int_equal(cdem_cli_wants_help(4, a4, 2, &help), 3);
}

static void test_cli_help_usage_error(void **state) {
    (void)state;
    char *t = printed(cdem_cli_usage_print, "missing the run file");
    assert_true(
        strncmp(t, "prog sub: missing the run file\nusage: prog sub RUN.h5 [--alpha A]", 63) == 0);
    assert_non_null(strstr(t, "\nTry 'prog sub --help' for more information.\n"));
    assert_null(strstr(t, "RUN.h5 --second")); /* the first form only */
    free(t);
}

/* An unknown long option gets the nearest spelling of the table (or --help) when it is
 * close; a far one and a one-letter option get none. */
static void test_cli_help_suggest_option(void **state) {
    (void)state;
    char buf[64];
    assert_string_equal(cdem_cli_suggest_option(&help, "--outptu", buf, sizeof buf), "--output");
    assert_string_equal(cdem_cli_suggest_option(&help, "--flga=1", buf, sizeof buf), "--flag");
    assert_string_equal(cdem_cli_suggest_option(&help, "--hlep", buf, sizeof buf), "--help");
    assert_null(cdem_cli_suggest_option(&help, "--nothing-like-it", buf, sizeof buf));
    assert_null(cdem_cli_suggest_option(&help, "-p", buf, sizeof buf));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cli_help_layout),         cmocka_unit_test(test_cli_help_find_option),
        cmocka_unit_test(test_cli_help_wants_help),     cmocka_unit_test(test_cli_help_usage_error),
        cmocka_unit_test(test_cli_help_suggest_option),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
