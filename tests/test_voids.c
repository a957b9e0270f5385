/* Tests of voids.[ch] (steepest surface slope, closed-off voids, open fissures) on synthetic
 * packings whose answers are known by construction. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis_fixtures.h"
#include "assert_near.h"
#include "voids.h"

/* A dense packing 8000 x 3000 m kept where keep_fn(x, y, r) holds, with the base row and two
 * tall lateral walls (boundary elements: solid, never measured). */
static void make_block(cdem_state *s, int (*keep_fn)(double, double, double)) {
    make_packing(s, 4000, 8000.0, 3000.0, 11);
    unsigned char *keep = malloc(s->n);
    assert_non_null(keep);
    for (size_t i = 0; i < s->n; i++)
        keep[i] = (s->flags[i] & CDEM_FLAGS_BOUNDARY) || keep_fn(s->x[i], s->y[i], s->radius[i]);
    cdem_state_compact(s, keep, NULL);
    free(keep);
    cdem_error err;
    for (double y = -50.0; y < 4000.0; y += 50.0) {
        assert_int_equal(
            cdem_state_append(s, -1, -60.0, y, 50.0, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
        assert_int_equal(
            cdem_state_append(s, -1, 8060.0, y, 50.0, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
    }
}

static int flat(double x, double y, double r) {
    (void)x;
    return y + r <= 2500.0;
}
static int cavity(double x, double y, double r) { /* a 400 m hole under 1.3 km of rock */
    return flat(x, y, r) && hypot(x - 4000.0, y - 1200.0) > 400.0;
}
static int cliff(double x, double y, double r) { /* 2 km step at x = 4000 m */
    return y + r <= (x < 4000.0 ? 2500.0 : 500.0);
}
static int slot(double x, double y, double r) { /* a 300 m slot down to 800 m */
    return flat(x, y, r) && !(fabs(x - 4000.0) < 150.0 && y > 800.0);
}

static cdem_voids_result measure(int (*keep_fn)(double, double, double)) {
    cdem_state s = {0};
    make_block(&s, keep_fn);
    cdem_voids_result r;
    cdem_error err;
    assert_int_equal(cdem_voids_measure(&s, 1000.0, &r, &err), CDEM_OK);
    cdem_state_free(&s);
    return r;
}

static void test_voids_intact_block(void **state) {
    (void)state;
    const cdem_voids_result r = measure(flat);
    assert_int_equal(r.n_voids, 0);
    assert_near(r.min_clearance, 125.0, 0.0);
    assert_near(r.window, 1000.0, 0.0);
    /* a sliding column of 17 cells of 1000 / 64 m: 2 r_max and a cell */
    assert_near(r.column_width, 17.0 * 1000.0 / 64.0, 1e-9);
    assert_true(r.largest_clearance < r.min_clearance); /* pores and pockets of the packing */
    assert_true(r.steepest_deg < 10.0);                 /* a flat top */
    assert_near(r.void_min_room, M_PI * 125.0 * 125.0 / 16.0, 1e-6);
    assert_true(r.fissure_depth < 500.0); /* notches where top elements are missing */
    assert_near(r.cell, 12.5, 1e-9);
}

static void test_voids_enclosed_cavity(void **state) {
    (void)state;
    const cdem_voids_result r = measure(cavity);
    assert_int_equal(r.n_voids, 1);
    /* the hole's radius less the elements' overhang into it */
    assert_true(r.largest_clearance > 300.0 && r.largest_clearance < 460.0);
    assert_near(r.largest_x, 4000.0, 150.0);
    assert_near(r.largest_y, 1200.0, 150.0);
    assert_true(r.void_area > 1e5 && r.void_area < M_PI * 400.0 * 400.0);
    assert_true(r.steepest_deg < 10.0); /* the surface does not see it */
}

static void test_voids_cliff(void **state) {
    (void)state;
    const cdem_voids_result r = measure(cliff);
    assert_int_equal(r.n_voids, 0); /* open to the sky */
    /* 2 km down over 1 km: atan(2) = 63.4 degrees, less a column's rounding */
    assert_true(r.steepest_deg > 58.0 && r.steepest_deg < 66.0);
    assert_true(r.steepest_x0 < 4000.0 && r.steepest_x1 > 4000.0);
    assert_near(r.steepest_x1 - r.steepest_x0, 1000.0, 1e-9); /* exactly the window */
}

/* A flat lattice block, 80 x 25 elements of radius 50 m (top 2500 m, free extent 0-8000 m),
 * with `n_foot` elements of radius 10 m at its right foot, from x = 8010 m: as at a moving
 * wall, where a few small elements low against the wall's face reach a little further than
 * the rest. (Cells of 6.25 m, the sliding column 17 of them: 106.25 m.) */
static cdem_voids_result lattice_with_foot(int n_foot) {
    cdem_state s = {0};
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 2100, 0, &err), CDEM_OK);
    for (int j = 0; j < 25; j++)
        for (int i = 0; i < 80; i++)
            assert_int_equal(cdem_state_append(&s, -1, 50.0 + 100.0 * i, 50.0 + 100.0 * j, 50.0,
                                               1.0, 0, 0, 0, NULL, &err),
                             CDEM_OK);
    for (int k = 0; k < n_foot; k++)
        assert_int_equal(
            cdem_state_append(&s, -1, 8010.0 + 20.0 * k, 10.0, 10.0, 1.0, 0, 0, 0, NULL, &err),
            CDEM_OK);
    cdem_voids_result r;
    assert_int_equal(cdem_voids_measure(&s, 1000.0, &r, &err), CDEM_OK);
    cdem_state_free(&s);
    return r;
}

static void test_voids_no_false_cliff_at_the_foot(void **state) {
    (void)state;
    /* fixed columns of exactly 2 r_max = 100 m from x = 0 made the last one [8000, 8100) m,
     * holding only the small elements at the foot: a false cliff of atan(2480 / 1000) = 68
     * degrees. A column wholly inside the extent always holds some of the block's edge. */
    for (int n_foot = 1; n_foot <= 2; n_foot++) {
        const cdem_voids_result r = lattice_with_foot(n_foot);
        print_message("%d element(s) at the foot: steepest %.2f deg, columns %.3f m\n", n_foot,
                      r.steepest_deg, r.column_width);
        assert_near(r.column_width, 106.25, 1e-9);
        assert_near(r.steepest_deg, 0.0, 1e-9); /* the lattice's top is flat */
    }
}

/* The slope is taken over exactly the window, wherever the elements fall: a 500 m step reads
 * atan(500 / 1000). (One element of radius 40 m every 70 m. With fixed columns of 80 m from
 * the extent's start, the slope taken to the first column at least 1000 m away, it read less:
 * atan(500 / 1040) when that column was 1040 m away.) */
static void test_voids_slope_over_exact_window(void **state) {
    (void)state;
    for (int shift = 0; shift < 4; shift++) {
        cdem_state s = {0};
        cdem_error err;
        assert_int_equal(cdem_state_init(&s, 256, 0, &err), CDEM_OK);
        for (int k = 0; k < 86; k++) {
            const double x = 70.0 * k + 23.0 * shift, top = x < 3000.0 ? 1000.0 : 1500.0;
            assert_int_equal(
                cdem_state_append(&s, -1, x, top - 40.0, 40.0, 1.0, 0, 0, 0, NULL, &err), CDEM_OK);
        }
        cdem_voids_result r;
        assert_int_equal(cdem_voids_measure(&s, 1000.0, &r, &err), CDEM_OK);
        print_message("shift %d: steepest %.3f deg from x = %.1f to %.1f m\n", shift,
                      r.steepest_deg, r.steepest_x0, r.steepest_x1);
        assert_near(r.steepest_deg, atan(0.5) * 180.0 / M_PI, 1e-9);
        assert_near(r.steepest_x1 - r.steepest_x0, 1000.0, 1e-9);
        /* the step lies between the slope's ends */
        assert_true(r.steepest_x0 < 3000.0 && r.steepest_x1 >= 3000.0);
        cdem_state_free(&s);
    }
}

static void test_voids_open_slot(void **state) {
    (void)state;
    /* a 300 m slot open to the sky: the big probe (250 m across) does not get far down it, so
     * it is a closed-off room for the largest element: a crack between separating blocks */
    const cdem_voids_result r = measure(slot);
    assert_true(r.n_voids >= 1);
    /* and an open fissure from the top (2500 m) to the slot's floor (800 m) */
    assert_true(r.fissure_depth > 1400.0 && r.fissure_depth < 1800.0);
    assert_near(r.fissure_x, 4000.0, 200.0);
    assert_near(r.fissure_width, 250.0, 0.0);
}

static void test_voids_bad_input(void **state) {
    (void)state;
    cdem_state s = {0};
    cdem_error err;
    cdem_voids_result r;
    assert_int_equal(cdem_state_init(&s, 8, 0, &err), CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, 0.0, 0.0, 50.0, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_voids_measure(&s, 1000.0, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "no free element"));
    assert_int_equal(cdem_state_append(&s, -1, 0.0, 100.0, 50.0, 1.0, 1, 0, 0, NULL, &err),
                     CDEM_OK);
    assert_int_equal(cdem_voids_measure(&s, 0.0, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "window = 0"));
    assert_int_equal(cdem_voids_measure(&s, NAN, &r, &err), CDEM_ERR_INVALID);
    /* a window shorter than the largest element's diameter (100 m) */
    assert_int_equal(cdem_voids_measure(&s, 99.0, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "window = 99 m: must be at least the largest element's "
                                    "diameter (100 m)"));
    assert_int_equal(cdem_voids_measure(&s, 1000.0, &r, &err), CDEM_OK); /* one element */
    assert_int_equal(r.n_voids, 0);
    /* no two heights a window apart: no slope, whatever the window (1e20 m overflowed the
     * cell count once) */
    assert_near(r.steepest_deg, 0.0, 0.0);
    assert_near(r.steepest_x1, r.steepest_x0, 0.0);
    assert_int_equal(cdem_voids_measure(&s, 1e20, &r, &err), CDEM_OK);
    assert_near(r.steepest_deg, 0.0, 0.0);
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_voids_intact_block),
        cmocka_unit_test(test_voids_enclosed_cavity),
        cmocka_unit_test(test_voids_cliff),
        cmocka_unit_test(test_voids_open_slot),
        cmocka_unit_test(test_voids_bad_input),
        cmocka_unit_test(test_voids_no_false_cliff_at_the_foot),
        cmocka_unit_test(test_voids_slope_over_exact_window),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
