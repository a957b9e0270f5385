/* analysis/cellgrid: the bucket grid behind the strain fit's neighbour queries. Known
 * answers on a hand-made set (cell of each point, order within a cell, left-out points),
 * the clipped cell ranges of a query, the cell enlargement that keeps memory O(n), the
 * error on a bad cell size, and a randomised check that the 3 x 3 cells a query visits
 * hold every point within the radius (compared with a brute-force search). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cellgrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The cell (ix, iy) that holds point i, found by scanning the grid's items. */
static void cell_of(const cdem_cellgrid *g, size_t i, size_t *ix, size_t *iy) {
    for (size_t c = 0; c < g->nx * g->ny; c++)
        for (size_t k = g->start[c]; k < g->start[c + 1]; k++)
            if (g->items[k] == i) {
                *ix = c % g->nx;
                *iy = c / g->nx;
                return;
            }
    fail_msg("point %zu is in no cell", i);
}

static void test_cellgrid_known_cells(void **state) {
    (void)state;
    /* bounding box (1, 2)..(4.5, 3.9), cell 1: 4 x 2 cells from (1, 2) */
    const double x[] = {1.0, 4.5, 2.2, 1.9, 3.0, NAN, 2.5};
    const double y[] = {2.0, 3.9, 2.1, 2.9, 3.0, 2.0, 2.5};
    const unsigned char include[] = {1, 1, 1, 1, 1, 1, 0};
    cdem_cellgrid g;
    cdem_error err;
    assert_int_equal(cdem_cellgrid_build(&g, x, y, 7, include, 1.0, &err), CDEM_OK);
    assert_true(g.x0 == 1.0 && g.y0 == 2.0 && g.cell == 1.0);
    assert_int_equal(g.nx, 4);
    assert_int_equal(g.ny, 2);
    /* the NaN point and the excluded one are left out: 5 items */
    assert_int_equal(g.start[g.nx * g.ny], 5);
    static const size_t want[][2] = {{0, 0}, {3, 1}, {1, 0}, {0, 0}, {2, 1}};
    for (size_t i = 0; i < 5; i++) {
        size_t ix = SIZE_MAX, iy = SIZE_MAX;
        cell_of(&g, i, &ix, &iy);
        if (ix != want[i][0] || iy != want[i][1])
            fail_msg("point %zu: cell (%zu, %zu), expected (%zu, %zu)", i, ix, iy, want[i][0],
                     want[i][1]);
    }
    /* cell (0, 0) holds points 0 and 3 in ascending order */
    assert_int_equal(g.start[1] - g.start[0], 2);
    assert_int_equal(g.items[g.start[0]], 0);
    assert_int_equal(g.items[g.start[0] + 1], 3);
    /* a query square around (2.5, 2.5) of half-width 0.6 covers cells x 0..2, y 0..1 */
    size_t ix0, ix1, iy0, iy1;
    assert_int_equal(cdem_cellgrid_range(&g, 2.5, 2.5, 0.6, &ix0, &ix1, &iy0, &iy1), 1);
    assert_int_equal(ix0, 0);
    assert_int_equal(ix1, 2);
    assert_int_equal(iy0, 0);
    assert_int_equal(iy1, 1);
    /* clipped at the grid's edges */
    assert_int_equal(cdem_cellgrid_range(&g, 0.0, 0.0, 2.5, &ix0, &ix1, &iy0, &iy1), 1);
    assert_int_equal(ix0, 0);
    assert_int_equal(ix1, 1);
    assert_int_equal(iy0, 0);
    assert_int_equal(iy1, 0);
    /* a square that misses the grid, a NaN position, a negative radius: nothing to visit */
    assert_int_equal(cdem_cellgrid_range(&g, 100.0, 2.5, 1.0, &ix0, &ix1, &iy0, &iy1), 0);
    assert_int_equal(cdem_cellgrid_range(&g, NAN, 2.5, 1.0, &ix0, &ix1, &iy0, &iy1), 0);
    assert_int_equal(cdem_cellgrid_range(&g, 2.5, 2.5, -1.0, &ix0, &ix1, &iy0, &iy1), 0);
    cdem_cellgrid_free(&g);
    assert_null(g.start);
    cdem_cellgrid_free(NULL);
}

static void test_cellgrid_far_point_enlarges_cells(void **state) {
    (void)state;
    /* 10 points near the origin and one 1e6 cells away: the cell doubles until the grid
     * has at most 4 n + 64 cells, and every point still lands in one */
    double x[11], y[11];
    for (int i = 0; i < 10; i++) {
        x[i] = 0.1 * i;
        y[i] = 0.05 * i;
    }
    x[10] = 1e6;
    y[10] = 1e6;
    cdem_cellgrid g;
    cdem_error err;
    assert_int_equal(cdem_cellgrid_build(&g, x, y, 11, NULL, 1.0, &err), CDEM_OK);
    assert_true((double)(g.nx * g.ny) <= 4.0 * 11 + 64);
    assert_true(g.cell > 1.0);
    assert_true(g.cell == ldexp(1.0, (int)round(log2(g.cell)))); /* a power of two times 1 */
    assert_int_equal(g.start[g.nx * g.ny], 11);
    cdem_cellgrid_free(&g);
    /* no usable point: one empty cell */
    const double nan1[] = {NAN};
    assert_int_equal(cdem_cellgrid_build(&g, nan1, nan1, 1, NULL, 1.0, &err), CDEM_OK);
    assert_int_equal(g.nx * g.ny, 1);
    assert_int_equal(g.start[1], 0);
    cdem_cellgrid_free(&g);
}

static void test_cellgrid_refuses_bad_cell(void **state) {
    (void)state;
    const double x[] = {0.0}, y[] = {0.0};
    const double bad[] = {0.0, -1.0, NAN, INFINITY};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        cdem_cellgrid g;
        cdem_error err;
        assert_int_equal(cdem_cellgrid_build(&g, x, y, 1, NULL, bad[k], &err), CDEM_ERR_INVALID);
        assert_non_null(strstr(err.msg, "must be finite and > 0"));
        assert_null(g.start);
    }
}

/* splitmix64: a seeded generator (no clock). */
static double uniform(uint64_t *s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (double)((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
}

static void test_cellgrid_queries_match_brute_force(void **state) {
    (void)state;
    enum { N = 400 };
    double x[N], y[N];
    uint64_t seed = 20261126u;
    for (int i = 0; i < N; i++) {
        x[i] = 100.0 * uniform(&seed);
        y[i] = 40.0 * uniform(&seed);
    }
    const double r = 7.5;
    cdem_cellgrid g;
    cdem_error err;
    assert_int_equal(cdem_cellgrid_build(&g, x, y, N, NULL, r, &err), CDEM_OK);
    for (int q = 0; q < N; q += 7) {
        size_t ix0, ix1, iy0, iy1, found = 0, expected = 0;
        assert_int_equal(cdem_cellgrid_range(&g, x[q], y[q], r, &ix0, &ix1, &iy0, &iy1), 1);
        assert_true(ix1 - ix0 <= 2 && iy1 - iy0 <= 2); /* at most 3 x 3 cells */
        unsigned char seen[N] = {0};
        for (size_t iy = iy0; iy <= iy1; iy++)
            for (size_t ix = ix0; ix <= ix1; ix++) {
                size_t c = iy * g.nx + ix, prev = SIZE_MAX;
                for (size_t k = g.start[c]; k < g.start[c + 1]; k++) {
                    const size_t j = g.items[k];
                    assert_true(prev == SIZE_MAX || j > prev); /* ascending in a cell */
                    prev = j;
                    seen[j] = 1;
                }
            }
        for (int j = 0; j < N; j++)
            if (hypot(x[j] - x[q], y[j] - y[q]) <= r) {
                expected++;
                if (!seen[j])
                    fail_msg("query %d: point %d at distance <= r not visited", q, j);
                found++;
            }
        assert_int_equal(found, expected);
        assert_true(expected >= 1); /* the point itself */
    }
    cdem_cellgrid_free(&g);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cellgrid_known_cells),
        cmocka_unit_test(test_cellgrid_far_point_enlarges_cells),
        cmocka_unit_test(test_cellgrid_refuses_bad_cell),
        cmocka_unit_test(test_cellgrid_queries_match_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
