/* analysis/csvtable: the numeric CSV reader of the wedge tables and plot-csv. A table
 * round trip (names trimmed, comments and blank lines skipped, nan/inf read), column
 * look-up, and every refusal naming the file, line, column and text. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "csvtable.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Writes text to the scratch file name; its path in path. */
static void write_file(const char *name, const char *text, char *path, size_t cap) {
    scratch_path(path, cap, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void test_csvtable_round_trip(void **state) {
    (void)state;
    char path[1024];
    write_file("table.csv",
               "# a comment before the header\n"
               " time , shortening,angle \n"
               "\n"
               "0, 0.5, 12\n"
               "# a comment between rows\n"
               "1e3,-2.25,nan\n"
               "  2000 , 7 , inf\n",
               path, sizeof path);
    cdem_csvtable t;
    cdem_error err;
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_OK);
    assert_int_equal(t.n_cols, 3);
    assert_int_equal(t.n_rows, 3);
    assert_string_equal(t.names[0], "time");
    assert_string_equal(t.names[1], "shortening");
    assert_string_equal(t.names[2], "angle");
    const double want[] = {0, 0.5, 12, 1000, -2.25, NAN, 2000, 7, INFINITY};
    for (size_t k = 0; k < 9; k++) {
        if (isnan(want[k]))
            assert_true(isnan(t.values[k]));
        else
            assert_true(t.values[k] == want[k]);
    }
    size_t col = 99;
    assert_int_equal(cdem_csvtable_find(&t, "shortening", path, &col, &err), CDEM_OK);
    assert_int_equal(col, 1);
    double column[3];
    cdem_csvtable_column(&t, col, column);
    assert_true(column[0] == 0.5 && column[1] == -2.25 && column[2] == 7.0);
    /* an unknown column is refused, naming the file and listing the columns */
    assert_int_equal(cdem_csvtable_find(&t, "dip", path, &col, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "no column 'dip'; the columns are: time, shortening, angle"));
    assert_non_null(strstr(err.msg, path));
    cdem_csvtable_free(&t);
    assert_null(t.names);
    cdem_csvtable_free(NULL);
    /* a header alone is a table of no rows */
    write_file("header.csv", "a,b\n", path, sizeof path);
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_OK);
    assert_int_equal(t.n_cols, 2);
    assert_int_equal(t.n_rows, 0);
    cdem_csvtable_free(&t);
}

static void test_csvtable_refusals(void **state) {
    (void)state;
    static const struct {
        const char *text; /* file contents */
        cdem_status code; /* expected status */
        const char *want; /* in the message, after "<path>" */
    } bad[] = {
        {"a,b\n1,2\n3,x\n", CDEM_ERR_PARSE, ":3: column 2 (b): 'x' is not a number"},
        {"a,b\n1\n", CDEM_ERR_PARSE,
         ":2: column 1 (a): '1' is not a number (or the line has too few"},
        {"a,b\n1,2,3\n", CDEM_ERR_PARSE,
         ":2: column 2 (b): '2,3' is not a number (or the line has too many"},
        {"a,,c\n", CDEM_ERR_PARSE, ":1: column 2 has an empty name"},
        {"\x01\x02,b\n", CDEM_ERR_PARSE, ":1: the header line is not text"},
        {"# only a comment\n\n", CDEM_ERR_PARSE, ": empty file: a header line of column names"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char path[1024], name[32];
        snprintf(name, sizeof name, "bad%zu.csv", k);
        write_file(name, bad[k].text, path, sizeof path);
        cdem_csvtable t;
        cdem_error err;
        assert_int_equal(cdem_csvtable_read(path, &t, &err), bad[k].code);
        char want[1200];
        snprintf(want, sizeof want, "%s%s", path, bad[k].want);
        if (!strstr(err.msg, want))
            fail_msg("case %zu: message '%s' lacks '%s'", k, err.msg, want);
        assert_null(t.names); /* nothing left allocated */
        assert_null(t.values);
    }
    /* a missing file */
    char path[1024];
    scratch_path(path, sizeof path, "no-such-table.csv");
    cdem_csvtable t;
    cdem_error err;
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "cannot open"));
    assert_non_null(strstr(err.msg, "no-such-table.csv"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_csvtable_round_trip),
        cmocka_unit_test(test_csvtable_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
