/* common/grid: the one cell grid (neighbour search, assembly, sediment and surface columns,
 * the analysis queries). The geometry: the cell of a point on and next to cell edges, the
 * clamped and the "inside" column, clipped ranges, the 3 x 3 neighbourhood at the corners,
 * edges and inside of a grid, the fit to a box and its cell doubling. The counting sort:
 * stable order, left-out keys, offsets. The point index (cdem_grid_index): known answers on
 * a hand-made set (cell of each point, order within a cell, left-out points), the clipped
 * cell ranges of a query, the cell enlargement that keeps memory O(n), the error on a bad
 * cell size, and a randomised check that the 3 x 3 cells a query visits hold every point
 * within the radius (compared with a brute-force search). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A point on a cell edge belongs to the cell on its right/above; just left of it (the next
 * double down) to the one before. The clamped column puts points off the grid (and NaN)
 * into the edge cells; the "inside" column refuses them. */
static void test_grid_cell_of_point_at_edges(void **state) {
    (void)state;
    const cdem_grid g = {.x0 = -1.0, .y0 = 2.0, .cell = 0.5, .nx = 4, .ny = 3};
    assert_int_equal(cdem_grid_col(&g, -1.0), 0);
    assert_int_equal(cdem_grid_col(&g, -0.5), 1);                  /* on the edge of 0 and 1 */
    assert_int_equal(cdem_grid_col(&g, nextafter(-0.5, -1.0)), 0); /* just below it */
    assert_int_equal(cdem_grid_col(&g, 0.999), 3);
    assert_int_equal(cdem_grid_col(&g, 1.0), 3); /* right edge: clamped */
    assert_int_equal(cdem_grid_col(&g, 50.0), 3);
    assert_int_equal(cdem_grid_col(&g, nextafter(-1.0, -2.0)), 0); /* left of the grid */
    assert_int_equal(cdem_grid_col(&g, -INFINITY), 0);
    assert_int_equal(cdem_grid_col(&g, NAN), 0);
    assert_int_equal(cdem_grid_row(&g, 2.5), 1);
    assert_int_equal(cdem_grid_row(&g, nextafter(2.5, 0.0)), 0);
    assert_int_equal(cdem_grid_row(&g, 100.0), 2);
    /* row-major cell index, bottom row first */
    assert_int_equal(cdem_grid_cell(&g, -0.5, 2.5), 1 * 4 + 1);
    assert_int_equal(cdem_grid_cell(&g, 0.9, 3.4), 2 * 4 + 3);
    /* the unclamped coordinate is floor((v - origin) / cell), a division */
    assert_true(cdem_grid_coord(-1.5, -1.0, 0.5) == -1.0);
    assert_true(cdem_grid_coord(0.3, 0.0, 0.1) == 2.0); /* 0.3 / 0.1 = 2.9999999999999996 */
    size_t c = 99;
    assert_int_equal(cdem_grid_col_inside(&g, -1.0, &c), 1);
    assert_int_equal(c, 0);
    assert_int_equal(cdem_grid_col_inside(&g, 0.99, &c), 1);
    /* (1 - 2^-53) - (-1) rounds to 2: the last double below the right edge is outside */
    assert_int_equal(cdem_grid_col_inside(&g, nextafter(1.0, 0.0), &c), 0);
    assert_int_equal(c, 3);
    c = 99;
    assert_int_equal(cdem_grid_col_inside(&g, 1.0, &c), 0);
    assert_int_equal(cdem_grid_col_inside(&g, nextafter(-1.0, -2.0), &c), 0);
    assert_int_equal(cdem_grid_col_inside(&g, NAN, &c), 0);
    assert_int_equal(c, 99); /* untouched when outside */
    /* -0.0 against the origin 0: column 0, inside */
    const cdem_grid z = {.x0 = 0.0, .y0 = 0.0, .cell = 1.0, .nx = 2, .ny = 1};
    assert_int_equal(cdem_grid_col_inside(&z, -0.0, &c), 1);
    assert_int_equal(c, 0);
}

/* Inclusive column ranges of an interval, clipped; 0 when it misses the grid. */
static void test_grid_col_range(void **state) {
    (void)state;
    const cdem_grid g = {.x0 = 0.0, .y0 = 0.0, .cell = 1.0, .nx = 5, .ny = 2};
    size_t a = 0, b = 0;
    assert_int_equal(cdem_grid_col_range(&g, 1.5, 3.0, &a, &b), 1);
    assert_int_equal(a, 1);
    assert_int_equal(b, 3); /* 3.0 is on the left edge of column 3 */
    assert_int_equal(cdem_grid_col_range(&g, -7.0, 0.5, &a, &b), 1);
    assert_int_equal(a, 0);
    assert_int_equal(b, 0);
    assert_int_equal(cdem_grid_col_range(&g, 4.5, 70.0, &a, &b), 1);
    assert_int_equal(a, 4);
    assert_int_equal(b, 4);
    assert_int_equal(cdem_grid_col_range(&g, -3.0, -0.5, &a, &b), 0); /* left of the grid */
    assert_int_equal(cdem_grid_col_range(&g, 5.0, 6.0, &a, &b), 0);   /* right of it */
    assert_int_equal(cdem_grid_col_range(&g, NAN, 1.0, &a, &b), 0);
    assert_int_equal(cdem_grid_row_range(&g, 0.2, 1.7, &a, &b), 1);
    assert_int_equal(a, 0);
    assert_int_equal(b, 1);
    assert_int_equal(cdem_grid_row_range(&g, 2.0, 3.0, &a, &b), 0);
}

/* The 3 x 3 block around a cell, clipped at the corners and edges; a one-row grid. */
static void test_grid_around(void **state) {
    (void)state;
    const cdem_grid g = {.x0 = 0.0, .y0 = 0.0, .cell = 1.0, .nx = 4, .ny = 3};
    cdem_grid_box b = cdem_grid_around(&g, 0); /* bottom-left corner */
    assert_true(b.x_lo == 0 && b.x_hi == 1 && b.y_lo == 0 && b.y_hi == 1);
    b = cdem_grid_around(&g, 1 * 4 + 2); /* inside */
    assert_true(b.x_lo == 1 && b.x_hi == 3 && b.y_lo == 0 && b.y_hi == 2);
    b = cdem_grid_around(&g, 2 * 4 + 3); /* top-right corner */
    assert_true(b.x_lo == 2 && b.x_hi == 3 && b.y_lo == 1 && b.y_hi == 2);
    b = cdem_grid_around(&g, 1 * 4 + 0); /* left edge */
    assert_true(b.x_lo == 0 && b.x_hi == 1 && b.y_lo == 0 && b.y_hi == 2);
    const cdem_grid row = {.x0 = 0.0, .y0 = 0.0, .cell = 1.0, .nx = 1, .ny = 1};
    b = cdem_grid_around(&row, 0);
    assert_true(b.x_lo == 0 && b.x_hi == 0 && b.y_lo == 0 && b.y_hi == 0);
    /* every point within one cell side of a point of the cell lies in the block */
    const cdem_grid big = {.x0 = -3.0, .y0 = 1.0, .cell = 0.75, .nx = 9, .ny = 7};
    for (int k = 0; k < 2000; k++) {
        const double px = -3.0 + 6.75 * (k % 97) / 97.0, py = 1.0 + 5.25 * (k % 89) / 89.0;
        const double ang = 0.37 * k, d = 0.75 * (k % 13) / 13.0;
        const double qx = px + d * cos(ang), qy = py + d * sin(ang);
        if (!(qx >= -3.0 && qx < -3.0 + 9 * 0.75 && qy >= 1.0 && qy < 1.0 + 7 * 0.75))
            continue;
        const cdem_grid_box bb = cdem_grid_around(&big, cdem_grid_cell(&big, px, py));
        const size_t cx = cdem_grid_col(&big, qx), cy = cdem_grid_row(&big, qy);
        assert_true(cx >= bb.x_lo && cx <= bb.x_hi && cy >= bb.y_lo && cy <= bb.y_hi);
    }
}

/* Fit to a box: origin at its corner, floor(extent / cell) + 1 cells, doubling while there
 * are too many; an extent no finite cell fits gives one infinite cell and 0. */
static void test_grid_fit(void **state) {
    (void)state;
    cdem_grid g;
    assert_int_equal(cdem_grid_fit(&g, 1.0, 4.5, 2.0, 3.9, 1.0, 100.0), 1);
    assert_true(g.x0 == 1.0 && g.y0 == 2.0 && g.cell == 1.0);
    assert_int_equal(g.nx, 4);
    assert_int_equal(g.ny, 2);
    assert_int_equal(cdem_grid_fit(&g, 0.0, 3.0, 0.0, 0.0, 1.0, 100.0), 1);
    assert_int_equal(g.nx, 4); /* the box's right edge starts a cell of its own */
    assert_int_equal(cdem_grid_fit(&g, 0.0, 99.0, 0.0, 99.0, 1.0, 100.0), 1);
    assert_true(g.cell == 16.0); /* 100 x 100 > 100 ... 7 x 7 <= 100 */
    assert_int_equal(g.nx, 7);
    assert_int_equal(cdem_grid_fit(&g, -1e308, 1e308, 0.0, 0.0, 1.0, 100.0), 0);
    assert_true(isinf(g.cell));
    assert_int_equal(g.nx * g.ny, 1);
}

/* The counting sort: stable (ascending index within a key), negative keys left out, start
 * offsets of every key including the empty ones. */
static void test_grid_sort_order(void **state) {
    (void)state;
    const int32_t key[] = {2, 0, -1, 2, 0, 3, -5, 2, 0};
    int32_t start[5], items[9];
    memset(items, 0x7f, sizeof items);
    assert_int_equal(cdem_grid_sort(key, 9, 4, start, items), 7);
    static const int32_t want_start[] = {0, 3, 3, 6, 7};
    static const int32_t want_items[] = {1, 4, 8, 0, 3, 7, 5};
    for (int k = 0; k < 5; k++)
        assert_int_equal(start[k], want_start[k]);
    for (int k = 0; k < 7; k++)
        assert_int_equal(items[k], want_items[k]);
    assert_int_equal(items[7], 0x7f7f7f7f); /* nothing written past the sorted indices */
    /* no indices: every key empty */
    assert_int_equal(cdem_grid_sort(key, 0, 4, start, items), 0);
    for (int k = 0; k < 5; k++)
        assert_int_equal(start[k], 0);
}

/* The cell (ix, iy) that holds point i, found by scanning the grid's items. */
static void cell_of(const cdem_grid_index *g, size_t i, size_t *ix, size_t *iy) {
    for (size_t c = 0; c < g->grid.nx * g->grid.ny; c++)
        for (int32_t k = g->start[c]; k < g->start[c + 1]; k++)
            if ((size_t)g->items[k] == i) {
                *ix = c % g->grid.nx;
                *iy = c / g->grid.nx;
                return;
            }
    fail_msg("point %zu is in no cell", i);
}

static void test_index_known_cells(void **state) {
    (void)state;
    /* bounding box (1, 2)..(4.5, 3.9), cell 1: 4 x 2 cells from (1, 2) */
    const double x[] = {1.0, 4.5, 2.2, 1.9, 3.0, NAN, 2.5};
    const double y[] = {2.0, 3.9, 2.1, 2.9, 3.0, 2.0, 2.5};
    const unsigned char include[] = {1, 1, 1, 1, 1, 1, 0};
    cdem_grid_index g;
    cdem_error err;
    assert_int_equal(cdem_grid_index_build(&g, x, y, 7, include, 1.0, &err), CDEM_OK);
    assert_true(g.grid.x0 == 1.0 && g.grid.y0 == 2.0 && g.grid.cell == 1.0);
    assert_int_equal(g.grid.nx, 4);
    assert_int_equal(g.grid.ny, 2);
    /* the NaN point and the excluded one are left out: 5 items */
    assert_int_equal(g.start[g.grid.nx * g.grid.ny], 5);
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
    cdem_grid_box b;
    assert_int_equal(cdem_grid_index_range(&g, 2.5, 2.5, 0.6, &b), 1);
    assert_int_equal(b.x_lo, 0);
    assert_int_equal(b.x_hi, 2);
    assert_int_equal(b.y_lo, 0);
    assert_int_equal(b.y_hi, 1);
    /* clipped at the grid's edges */
    assert_int_equal(cdem_grid_index_range(&g, 0.0, 0.0, 2.5, &b), 1);
    assert_int_equal(b.x_lo, 0);
    assert_int_equal(b.x_hi, 1);
    assert_int_equal(b.y_lo, 0);
    assert_int_equal(b.y_hi, 0);
    /* a square that misses the grid, a NaN position, a negative radius: nothing to visit */
    assert_int_equal(cdem_grid_index_range(&g, 100.0, 2.5, 1.0, &b), 0);
    assert_int_equal(cdem_grid_index_range(&g, NAN, 2.5, 1.0, &b), 0);
    assert_int_equal(cdem_grid_index_range(&g, 2.5, 2.5, -1.0, &b), 0);
    cdem_grid_index_free(&g);
    assert_null(g.start);
    cdem_grid_index_free(NULL);
}

static void test_index_far_point_enlarges_cells(void **state) {
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
    cdem_grid_index g;
    cdem_error err;
    assert_int_equal(cdem_grid_index_build(&g, x, y, 11, NULL, 1.0, &err), CDEM_OK);
    assert_true((double)(g.grid.nx * g.grid.ny) <= 4.0 * 11 + 64);
    assert_true(g.grid.cell > 1.0);
    assert_true(g.grid.cell ==
                ldexp(1.0, (int)round(log2(g.grid.cell)))); /* a power of two times 1 */
    assert_int_equal(g.start[g.grid.nx * g.grid.ny], 11);
    cdem_grid_index_free(&g);
    /* no usable point: one empty cell */
    const double nan1[] = {NAN};
    assert_int_equal(cdem_grid_index_build(&g, nan1, nan1, 1, NULL, 1.0, &err), CDEM_OK);
    assert_int_equal(g.grid.nx * g.grid.ny, 1);
    assert_int_equal(g.start[1], 0);
    cdem_grid_index_free(&g);
}

static void test_index_refuses_bad_cell(void **state) {
    (void)state;
    const double x[] = {0.0}, y[] = {0.0};
    const double bad[] = {0.0, -1.0, NAN, INFINITY};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        cdem_grid_index g;
        cdem_error err;
        assert_int_equal(cdem_grid_index_build(&g, x, y, 1, NULL, bad[k], &err), CDEM_ERR_INVALID);
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

static void test_index_queries_match_brute_force(void **state) {
    (void)state;
    enum { N = 400 };
    double x[N], y[N];
    uint64_t seed = 20261126u;
    for (int i = 0; i < N; i++) {
        x[i] = 100.0 * uniform(&seed);
        y[i] = 40.0 * uniform(&seed);
    }
    const double r = 7.5;
    cdem_grid_index g;
    cdem_error err;
    assert_int_equal(cdem_grid_index_build(&g, x, y, N, NULL, r, &err), CDEM_OK);
    for (int q = 0; q < N; q += 7) {
        size_t found = 0, expected = 0;
        cdem_grid_box b;
        assert_int_equal(cdem_grid_index_range(&g, x[q], y[q], r, &b), 1);
        assert_true(b.x_hi - b.x_lo <= 2 && b.y_hi - b.y_lo <= 2); /* at most 3 x 3 cells */
        unsigned char seen[N] = {0};
        for (size_t iy = b.y_lo; iy <= b.y_hi; iy++)
            for (size_t ix = b.x_lo; ix <= b.x_hi; ix++) {
                size_t c = iy * g.grid.nx + ix, prev = SIZE_MAX;
                for (int32_t k = g.start[c]; k < g.start[c + 1]; k++) {
                    const size_t j = (size_t)g.items[k];
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
    cdem_grid_index_free(&g);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid_cell_of_point_at_edges),
        cmocka_unit_test(test_grid_col_range),
        cmocka_unit_test(test_grid_around),
        cmocka_unit_test(test_grid_fit),
        cmocka_unit_test(test_grid_sort_order),
        cmocka_unit_test(test_index_known_cells),
        cmocka_unit_test(test_index_far_point_enlarges_cells),
        cmocka_unit_test(test_index_refuses_bad_cell),
        cmocka_unit_test(test_index_queries_match_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
