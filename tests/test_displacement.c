/* test_displacement: displacement by id across reordering, removal and addition. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "assert_near.h"

#include "displacement.h"

#include <math.h>

static void test_displacement_by_id(void **st) {
    (void)st;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    cdem_state_init(&ref, 4, 0, &err);
    cdem_state_init(&cur, 4, 0, &err);
    cdem_state_append(&ref, 10, 0, 0, 1, 1, 1, 0, 0, NULL, &err);
    cdem_state_append(&ref, 11, 5, 5, 1, 1, 1, 0, 0, NULL, &err);
    cdem_state_append(&ref, 12, 9, 9, 1, 1, 1, 0, 0, NULL, &err); /* removed later */
    /* cur: reversed, 12 removed, 13 added */
    cdem_state_append(&cur, 13, 1, 1, 1, 1, 25, CDEM_FLAG_GROWTH, 4, NULL, &err);
    cdem_state_append(&cur, 11, 7, 2, 1, 1, 1, 0, 0, NULL, &err);
    cdem_state_append(&cur, 10, -1, 3, 1, 1, 1, 0, 0, NULL, &err);
    double ux[3] = {-9, -9, -9}, uy[3] = {-9, -9, -9};
    assert_int_equal(cdem_displacement_compute(&ref, &cur, NULL, ux, uy, &err), CDEM_OK);
    assert_true(isnan(ux[0]) && isnan(uy[0]));
    assert_near(ux[1], 2, 0);
    assert_near(uy[1], -3, 0);
    assert_near(ux[2], -1, 0);
    assert_near(uy[2], 3, 0);
    /* selection leaves unselected slots untouched */
    const unsigned char sel[3] = {0, 0, 1};
    ux[1] = 42;
    assert_int_equal(cdem_displacement_compute(&ref, &cur, sel, ux, uy, &err), CDEM_OK);
    assert_near(ux[1], 42, 0);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_displacement_by_id),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
