/* test_fault_file: the irregular-fault vertex reader (every error names file and line) and
 * the listric curve (dip law, k = 1, checked against its definition). */
#include "fault_file.h"

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#define X0  1400.0
#define TOL 25.0

static void data_path(char *buf, size_t n, const char *name) {
    const char *d = getenv("CDEM_TEST_DATA");
    snprintf(buf, n, "%s/%s", d && *d ? d : "tests/data", name);
}

/* Reads fixture `name`, expects `code` and every string of `needles` in the message. */
static void expect_error(const char *name, cdem_status code, const char *n1, const char *n2) {
    char path[1024];
    data_path(path, sizeof path, name);
    cdem_fault_polyline pl;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_fault_file_read(path, X0, TOL, &pl, &err), code);
    assert_non_null(strstr(err.msg, name));
    if (!strstr(err.msg, n1) || (n2 && !strstr(err.msg, n2)))
        fail_msg("message '%s' lacks '%s' / '%s'", err.msg, n1, n2 ? n2 : "");
    assert_int_equal(pl.n, 0);
    assert_null(pl.x);
}

static void test_fault_file_empty(void **st) {
    (void)st;
    expect_error("fault_empty.txt", CDEM_ERR_PARSE, "empty", NULL);
    expect_error("fault_comments_only.txt", CDEM_ERR_PARSE, "empty (3 lines", NULL);
}

static void test_fault_file_one_point(void **st) {
    (void)st;
    expect_error("fault_one_point.txt", CDEM_ERR_PARSE, "line 2: only one point", NULL);
}

static void test_fault_file_bad_first_point(void **st) {
    (void)st;
    expect_error("fault_bad_first.txt", CDEM_ERR_RANGE, "line 1: first point (1300, 0)",
                 "x = 1400 m, y = 0) within 25 m");
}

static void test_fault_file_not_monotonic(void **st) {
    (void)st;
    expect_error("fault_not_monotonic.txt", CDEM_ERR_RANGE, "line 3: point (1250, 800)",
                 "lower x and higher y than the previous point (1200, 500)");
}

static void test_fault_file_not_numeric(void **st) {
    (void)st;
    expect_error("fault_not_numeric.txt", CDEM_ERR_PARSE, "line 2: '1200 abc': field 2 is not",
                 NULL);
}

static void test_fault_file_extra_field(void **st) {
    (void)st;
    expect_error("fault_extra_field.txt", CDEM_ERR_PARSE, "line 2: '1200 500 7': extra field '7'",
                 NULL);
}

static void test_fault_file_missing(void **st) {
    (void)st;
    expect_error("fault_no_such_file.txt", CDEM_ERR_IO, "cannot open", NULL);
}

static void test_fault_file_crlf_comma_comments(void **st) {
    (void)st;
    char path[1024];
    data_path(path, sizeof path, "fault_crlf.txt");
    cdem_fault_polyline pl;
    cdem_error err;
    if (cdem_fault_file_read(path, X0, TOL, &pl, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    const double ex[4] = {1400, 1100, 1000, 950}, ey[4] = {0, 300, 900, 1500};
    assert_int_equal(pl.n, 4);
    for (int k = 0; k < 4; k++) {
        assert_float_equal(pl.x[k], ex[k], 1e-12);
        assert_float_equal(pl.y[k], ey[k], 1e-12);
    }
    /* interpolation, vertical extension above, distance */
    assert_float_equal(cdem_fault_file_x_at(&pl, 150.0), 1250.0, 1e-9);
    assert_float_equal(cdem_fault_file_x_at(&pl, 1200.0), 975.0, 1e-9);
    assert_float_equal(cdem_fault_file_x_at(&pl, 2000.0), 950.0, 1e-9);
    /* (1270, 170) is 20 sqrt(2) m off the first segment, perpendicular to it */
    assert_float_equal(cdem_fault_file_distance(&pl, 1270.0, 170.0), 20.0 * sqrt(2.0), 1e-9);
    cdem_fault_file_free(&pl);
    cdem_fault_file_free(&pl); /* idempotent */
    cdem_fault_file_free(NULL);
}

/* The listric curve's segment dips follow dip(y) = d0 + (90 - d0) (y/H)^k at the segment
 * midpoints: 30 deg at the base, 90 deg at the top. */
static void test_fault_file_listric_dip_law(void **st) {
    (void)st;
    cdem_fault_polyline pl;
    cdem_error err;
    const double H = 1000.0, d0 = 30.0;
    const size_t ns = 100;
    assert_int_equal(cdem_fault_file_listric(X0, H, d0, ns, &pl, &err), CDEM_OK);
    assert_int_equal(pl.n, ns + 1);
    assert_float_equal(pl.x[0], X0, 0.0);
    assert_float_equal(pl.y[ns], H, 1e-9);
    for (size_t k = 1; k <= ns; k++) {
        const double dip = atan2(pl.y[k] - pl.y[k - 1], pl.x[k - 1] - pl.x[k]) * 180.0 / M_PI;
        const double eta = ((double)k - 0.5) / (double)ns;
        assert_float_equal(dip, d0 + (90.0 - d0) * pow(eta, CDEM_LISTRIC_EXPONENT), 1e-9);
    }
    /* horizontal extent: H integral of cot(dip) = H ln(1 / sin d0) / (90 - d0 in rad) */
    const double d0r = d0 * M_PI / 180.0;
    assert_float_equal(X0 - pl.x[ns], H * log(1.0 / sin(d0r)) / (M_PI / 2.0 - d0r), 0.5);
    assert_true(pl.x[ns - 1] - pl.x[ns] < 0.05 * H / ns); /* nearly vertical at the top */
    cdem_fault_file_free(&pl);
    assert_int_equal(cdem_fault_file_listric(X0, H, 0.0, ns, &pl, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "fault_dip = 0 degrees: must be in (0, 90]"));
    assert_int_equal(cdem_fault_file_listric(X0, -1.0, 30.0, ns, &pl, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "height = -1 m"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fault_file_empty),
        cmocka_unit_test(test_fault_file_one_point),
        cmocka_unit_test(test_fault_file_bad_first_point),
        cmocka_unit_test(test_fault_file_not_monotonic),
        cmocka_unit_test(test_fault_file_not_numeric),
        cmocka_unit_test(test_fault_file_extra_field),
        cmocka_unit_test(test_fault_file_missing),
        cmocka_unit_test(test_fault_file_crlf_comma_comments),
        cmocka_unit_test(test_fault_file_listric_dip_law),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
