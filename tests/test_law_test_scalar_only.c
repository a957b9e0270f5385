/* The tests' law fixture (common/laws/law_test_scalar_only.h): a law without an AVX2 kernel,
 * registered by its file and its line in laws.def alone. It is a law of the kernel (its
 * formula through cdem_contact_touching; tests/test_integrate.c compares its scalar and
 * vector paths with every other registered law's) and no parameter file can name it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "law_fixtures.h"

#include <math.h>
#include <string.h>

/* law-fixture-1: the contact kernel runs its formula, mu Fn + C0 / 2, at a slip. */
static void test_law_test_scalar_only_formula(void **state) {
    (void)state;
    const double fy = law_fx_sliding_force(CDEM_LAW_TEST_SCALAR_ONLY);
    /* the force along t = (0, 1): the limit, to the rounding of the unit vector */
    const double limit = LAW_FX_MU * LAW_FX_FN + 0.5 * LAW_FX_C0;
    if (!(fabs(fy - limit) <= 1e-12 * limit))
        fail_msg("tangential force %.17g, expected mu Fn + C0 / 2 = %.17g", fy, limit);
    assert_string_equal(cdem_law_name(CDEM_LAW_TEST_SCALAR_ONLY), "test-scalar-only");
}

/* law-fixture-2: no parameter file can choose it, and a parameter set holding it is
 * refused. */
static void test_law_test_scalar_only_not_offered(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    assert_true(CDEM_LAW_TEST_SCALAR_ONLY >= CDEM_LAW_WORDS);
    assert_int_equal(cdem_params_override(&p, "material.granular_law=test-scalar-only", &err),
                     CDEM_ERR_RANGE);
    const char *list = strstr(err.msg, "must be one of ");
    assert_non_null(list);
    assert_null(strstr(list, "test-scalar-only")); /* the words offered do not name it */
    p.granular_law = CDEM_LAW_TEST_SCALAR_ONLY;
    assert_int_equal(cdem_params_validate(&p, NULL, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "granular_law"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_law_test_scalar_only_formula),
        cmocka_unit_test(test_law_test_scalar_only_not_offered),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
