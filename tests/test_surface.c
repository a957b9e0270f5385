/* common/surface: which element is the free surface of each vertical column. Known answers
 * on a hand-made state: by top the highest top (y + radius) wins, not the highest centre;
 * by centre (the solver's overburden) the highest centre; ties go to the lowest index;
 * walls, fault elements, non-finite positions and zero radii are never surface; the x
 * window and the column range leave elements out; empty columns say SIZE_MAX; the surface
 * height is the highest free top. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "surface.h"

#include <math.h>

/* Element indices of the hand-made state (columns of width 10 m from x = 0). */
enum {
    E_LOW_BIG,     /* column 0: centre 5, radius 4: top 9 (the surface) */
    E_HIGH_SMALL,  /* column 0: centre 7, radius 1: top 8 (higher centre, lower top) */
    E_WALL,        /* column 1: a wall element high above: not free */
    E_FAULT,       /* column 1: a fault element: not free */
    E_FREE1,       /* column 1: the only free element: top 3 */
    E_NAN,         /* column 2: NaN position: not free */
    E_ZERO_RADIUS, /* column 2: radius 0: not free */
    E_OUTSIDE,     /* x = 45: beyond the 4 columns */
    E_LEFT,        /* x = -1: left of column 0 */
    E_COL3,        /* column 3, x = 35 */
    N_ELEMENTS
};

static void make_state(cdem_state *s) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, N_ELEMENTS, 0, &err), CDEM_OK);
    static const struct {
        double x, y, r;
        uint32_t flags;
    } e[N_ELEMENTS] = {
        [E_LOW_BIG] = {2, 5, 4, 0},
        [E_HIGH_SMALL] = {8, 7, 1, 0},
        [E_WALL] = {12, 50, 1, CDEM_FLAG_WALL},
        [E_FAULT] = {14, 40, 1, CDEM_FLAG_FAULT},
        [E_FREE1] = {15, 2, 1, 0},
        [E_NAN] = {25, NAN, 1, 0},
        [E_ZERO_RADIUS] = {26, 30, 0, 0},
        [E_OUTSIDE] = {45, 99, 1, 0},
        [E_LEFT] = {-1, 99, 1, 0},
        [E_COL3] = {35, 1, 0.5, 0},
    };
    for (size_t i = 0; i < N_ELEMENTS; i++)
        assert_int_equal(
            cdem_state_append(s, -1, e[i].x, e[i].y, e[i].r, 1.0, 1, e[i].flags, 0, NULL, &err),
            CDEM_OK);
}

static void test_surface_is_free(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    static const int free_want[N_ELEMENTS] = {1, 1, 0, 0, 1, 0, 0, 1, 1, 1};
    for (size_t i = 0; i < N_ELEMENTS; i++)
        if (cdem_surface_is_free(&s, i) != free_want[i])
            fail_msg("element %zu: free %d, expected %d", i, cdem_surface_is_free(&s, i),
                     free_want[i]);
    cdem_state_free(&s);
}

static void test_surface_column_tops(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    size_t top[4];
    cdem_surface_column_tops(&s, 0.0, 10.0, 4, -INFINITY, INFINITY, top);
    assert_int_equal(top[0], E_LOW_BIG);
    assert_int_equal(top[1], E_FREE1);
    assert_int_equal(top[2], SIZE_MAX); /* only unusable elements */
    assert_int_equal(top[3], E_COL3);
    /* a window x < 5 keeps only E_LOW_BIG's centre (x = 2) in column 0 */
    cdem_surface_column_tops(&s, 0.0, 10.0, 4, 0.0, 5.0, top);
    assert_int_equal(top[0], E_LOW_BIG);
    assert_int_equal(top[1], SIZE_MAX);
    assert_int_equal(top[3], SIZE_MAX);
    /* shifted origin: columns start at x = -5, so E_LEFT (x = -1) and E_LOW_BIG (x = 2)
     * share column 0 and E_LEFT's top (100) wins */
    cdem_surface_column_tops(&s, -5.0, 10.0, 4, -INFINITY, INFINITY, top);
    assert_int_equal(top[0], E_LEFT);
    assert_int_equal(top[1], E_HIGH_SMALL); /* x = 8: alone in column 1 */
    /* a zero width: every column empty */
    cdem_surface_column_tops(&s, 0.0, 0.0, 4, -INFINITY, INFINITY, top);
    for (size_t c = 0; c < 4; c++)
        assert_int_equal(top[c], SIZE_MAX);
    cdem_state_free(&s);
}

static void test_surface_by_centre(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    size_t top[4];
    const cdem_grid cols = {.x0 = 0.0, .y0 = 0.0, .cell = 10.0, .nx = 4, .ny = 1};
    cdem_surface_columns(&s, &cols, CDEM_SURFACE_BY_CENTRE, -INFINITY, INFINITY, top);
    assert_int_equal(top[0], E_HIGH_SMALL); /* centre 7 above centre 5 */
    assert_int_equal(top[1], E_FREE1);
    assert_int_equal(top[2], SIZE_MAX);
    assert_int_equal(top[3], E_COL3);
    cdem_surface_columns(&s, &cols, CDEM_SURFACE_BY_TOP, -INFINITY, INFINITY, top);
    assert_int_equal(top[0], E_LOW_BIG); /* the same as cdem_surface_column_tops */
    /* a tie: a copy of E_COL3 appended later does not take its column */
    cdem_error err;
    size_t idx = 0;
    assert_int_equal(cdem_state_append(&s, -1, 36.0, 1.0, 0.5, 1.0, 1, 0, 0, &idx, &err), CDEM_OK);
    cdem_surface_columns(&s, &cols, CDEM_SURFACE_BY_CENTRE, -INFINITY, INFINITY, top);
    assert_int_equal(top[3], E_COL3);
    cdem_surface_columns(&s, &cols, CDEM_SURFACE_BY_TOP, -INFINITY, INFINITY, top);
    assert_int_equal(top[3], E_COL3);
    cdem_state_free(&s);
}

static void test_surface_top(void **state) {
    (void)state;
    cdem_state s;
    make_state(&s);
    /* E_LEFT and E_OUTSIDE (centre 99, radius 1) are free: top 100; the wall and the fault
     * element above them do not count */
    assert_true(cdem_surface_top(&s) == 100.0);
    cdem_state_free(&s);
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 1, 0, &err), CDEM_OK);
    assert_true(cdem_surface_top(&s) == -INFINITY); /* no elements */
    assert_int_equal(
        cdem_state_append(&s, -1, 0.0, 500.0, 1.0, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err), CDEM_OK);
    assert_true(cdem_surface_top(&s) == -INFINITY); /* only a wall */
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_surface_is_free),
        cmocka_unit_test(test_surface_column_tops),
        cmocka_unit_test(test_surface_by_centre),
        cmocka_unit_test(test_surface_top),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
