/* test_limits: percentile definition against hand-computed values and GSL, colour limits
 * for magnitude, signed and capped quantities, the only-above mode and bad input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "assert_near.h"

#include "colorlimits.h"

#include <math.h>
#include <string.h>

static void test_limits_quantile_hand_computed(void **st) {
    (void)st;
    /* 1..5: h = 4 f; f = 0.01 -> 1 + 0.04 = 1.04; f = 0.99 -> 4 + 0.96 = 4.96; median 3 */
    const double v[5] = {1, 2, 3, 4, 5};
    assert_near(cdem_limits_quantile_sorted(v, 5, 0.01), 1.04, 1e-14);
    assert_near(cdem_limits_quantile_sorted(v, 5, 0.99), 4.96, 1e-14);
    assert_near(cdem_limits_quantile_sorted(v, 5, 0.5), 3.0, 1e-14);
    assert_near(cdem_limits_quantile_sorted(v, 5, 0.0), 1.0, 0);
    assert_near(cdem_limits_quantile_sorted(v, 5, 1.0), 5.0, 0);
    /* 0..100 (101 values): the 1st and 99th percentiles are exactly 1 and 99 */
    double w[101];
    for (int i = 0; i <= 100; i++)
        w[i] = i;
    assert_near(cdem_limits_quantile_sorted(w, 101, 0.01), 1.0, 1e-12);
    assert_near(cdem_limits_quantile_sorted(w, 101, 0.99), 99.0, 1e-12);
}

static void test_limits_percentiles_ignore_nan_and_order(void **st) {
    (void)st;
    /* unsorted, with NaN and Inf: finite values are 5 4 3 2 1 */
    const double v[8] = {5, NAN, 1, 4, INFINITY, 3, 2, NAN};
    cdem_limits l;
    cdem_error err;
    assert_int_equal(cdem_limits_from_values(v, 8, 0.01, 0.99, 0, 0, &l, &err), CDEM_OK);
    assert_near(l.vmin, 1.04, 1e-14);
    assert_near(l.vmax, 4.96, 1e-14);
    assert_int_equal(l.count, 5);
    assert_near(l.threshold, 0.496, 1e-14);
    assert_true(cdem_limits_above(&l, 0.5));
    assert_false(cdem_limits_above(&l, 0.4));
    assert_false(cdem_limits_above(&l, NAN));
}

static void test_limits_signed_symmetric(void **st) {
    (void)st;
    const double v[5] = {-10, -1, 0, 1, 3};
    cdem_limits l;
    cdem_error err;
    assert_int_equal(cdem_limits_from_values(v, 5, 0.0, 1.0, 1, 0, &l, &err), CDEM_OK);
    assert_near(l.vmin, -10, 0);
    assert_near(l.vmax, 10, 0);
    assert_true(cdem_limits_above(&l, -1.5)); /* magnitude counts in signed mode */
    assert_false(cdem_limits_above(&l, -0.5));
}

static void test_limits_stress_cap(void **st) {
    (void)st;
    const double v[4] = {-5e8, 1e6, 2e6, 9e8};
    cdem_limits l;
    cdem_error err;
    assert_int_equal(cdem_limits_from_values(v, 4, 0.0, 1.0, 0, CDEM_LIMITS_STRESS_CAP, &l, &err),
                     CDEM_OK);
    assert_near(l.vmin, -200e6, 0);
    assert_near(l.vmax, 200e6, 0);
}

static void test_limits_empty_and_fixed(void **st) {
    (void)st;
    const double v[2] = {NAN, NAN};
    cdem_limits l;
    cdem_error err;
    assert_int_equal(cdem_limits_from_values(v, 2, 0.01, 0.99, 0, 0, &l, &err), CDEM_OK);
    assert_int_equal(l.count, 0);
    assert_true(l.vmin == 0.0 && l.vmax == 0.0);
    l = cdem_limits_fixed(0.0, 0.1);
    assert_near(l.threshold, 0.01, 1e-15);
    assert_int_equal(cdem_limits_from_values(v, 2, 0.9, 0.1, 0, 0, &l, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "quantiles 0.9 and 0.1"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_limits_quantile_hand_computed),
        cmocka_unit_test(test_limits_percentiles_ignore_nan_and_order),
        cmocka_unit_test(test_limits_signed_symmetric),
        cmocka_unit_test(test_limits_stress_cap),
        cmocka_unit_test(test_limits_empty_and_fixed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
