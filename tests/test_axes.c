/* test_axes: grid axes of homogeneous strain and uniform stress, nodes on walls skipped. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "assert_near.h"

#include "analysis_fixtures.h"
#include "axes.h"

#include <math.h>
#include <string.h>

static void test_axes_pure_shear_directions(void **st) {
    (void)st;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    make_packing(&ref, 300, 3600.0, 2000.0, 4);
    cdem_state_copy(&cur, &ref, &err);
    /* shortening along x: S1 vertical, S3 horizontal */
    const double F[4] = {0.9, 0, 0, 1 / 0.9};
    deform_affine(&cur, F, 0, 0);
    cdem_axes ax;
    assert_int_equal(cdem_axes_strain(&ref, &cur, 0.0, &ax, &err), CDEM_OK);
    assert_near(ax.spacing, 250.0, 0);
    assert_true(ax.n > 40);
    size_t near_base = 0;
    const double want = (1 / 0.81 - 0.81) / 2; /* (l1 - l3) / 2 with S1 S3 = 1 */
    for (size_t k = 0; k < ax.n; k++) {
        assert_near(fabs(ax.angle1[k]), 90.0, 1e-8);
        assert_near(ax.angle3[k], 0.0, 1e-8);
        assert_near(fabs(ax.shear_a[k]), 45.0, 1e-8);
        assert_near(fabs(ax.shear_b[k]), 45.0, 1e-8);
        assert_near(ax.value[k], want, 1e-10);
        /* no node whose nearest element (brute force) is a wall element */
        size_t best = 0;
        double bd = INFINITY;
        for (size_t i = 0; i < cur.n; i++) {
            double d = hypot(cur.x[i] - ax.x[k], cur.y[i] - ax.y[k]);
            if (d < bd) {
                bd = d;
                best = i;
            }
        }
        assert_int_equal(cur.flags[best] & CDEM_FLAG_WALL, 0);
        if (ax.y[k] < 0.0)
            near_base++;
    }
    assert_int_equal(near_base, 0); /* the grid starts at the wall row (y = -50) */
    cdem_axes_free(&ax);
    cdem_axes_free(NULL);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

static void test_axes_skip_wall_nodes(void **st) {
    (void)st;
    /* a state made only of wall elements has no axes at all */
    cdem_state s = {0};
    cdem_error err;
    cdem_state_init(&s, 8, 1, &err);
    for (int i = 0; i < 8; i++)
        cdem_state_append(&s, -1, 100.0 * i, 0, 50, 1, 0, CDEM_FLAG_WALL, 0, NULL, &err);
    cdem_axes ax;
    assert_int_equal(cdem_axes_strain(&s, &s, 0.0, &ax, &err), CDEM_OK);
    assert_int_equal(ax.n, 0);
    cdem_axes_free(&ax);
    assert_int_equal(cdem_axes_stress(&s, 0.0, &ax, &err), CDEM_OK);
    assert_int_equal(ax.n, 0);
    cdem_axes_free(&ax);
    cdem_state_free(&s);
}

static void test_axes_uniform_stress(void **st) {
    (void)st;
    cdem_state s = {0};
    cdem_error err;
    make_packing(&s, 200, 3000.0, 1500.0, 8);
    assert_int_equal(cdem_axes_stress(&s, 0.0, &(cdem_axes){0}, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "stores no stress"));
    cdem_state_enable_stress(&s, &err);
    for (size_t i = 0; i < s.n; i++) {
        s.sxx[i] = 30e6;
        s.syy[i] = 10e6;
        s.sxy[i] = 10e6;
    }
    cdem_axes ax;
    assert_int_equal(cdem_axes_stress(&s, 0.0, &ax, &err), CDEM_OK);
    assert_true(ax.n > 20);
    for (size_t k = 0; k < ax.n; k++) {
        assert_near(ax.angle1[k], 22.5, 1e-9);
        assert_near(ax.angle3[k], -67.5, 1e-9);
        assert_near(ax.value[k], sqrt(2) * 10e6, 1e-3);
    }
    cdem_axes_free(&ax);
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_axes_pure_shear_directions),
        cmocka_unit_test(test_axes_skip_wall_nodes),
        cmocka_unit_test(test_axes_uniform_stress),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
