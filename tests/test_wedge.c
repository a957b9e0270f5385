/* Tests of wedge.[ch] (accretionary-wedge measurements), csvtable.[ch], the wedge and
 * plot-csv subcommands, and an end-to-end short detachment run ($CDEM_BUILD/cdem-run). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "analysis.h"
#include "assert_near.h"
#include "csvtable.h"
#include "h5format.h"
#include "params.h"
#include "wedge.h"
#include "scratch.h"

static const double deg = 3.14159265358979323846 / 180.0;

/* A square lattice of discs of radius 50 m: n_cols columns (x = 50 + 100 c) of n_rows rows
 * (y = 50 + 100 j), a fixed left wall column at x = -50, a base row at y = -50 and a moving
 * right wall column at x = 100 n_cols + 50 (inner face at 100 n_cols). */
static void make_lattice(cdem_state *s, int n_cols, int n_rows) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, 64, 0, &err), CDEM_OK);
    for (int c = 0; c < n_cols; c++)
        for (int j = 0; j < n_rows; j++)
            assert_int_equal(cdem_state_append(s, -1, 50.0 + 100.0 * c, 50.0 + 100.0 * j, 50.0, 1.0,
                                               1, 0, 0, NULL, &err),
                             CDEM_OK);
    for (int j = 0; j < 3 * n_rows; j++) {
        assert_int_equal(cdem_state_append(s, -1, -50.0, 50.0 + 100.0 * j, 50.0, 1.0, 0,
                                           CDEM_FLAG_WALL, 0, NULL, &err),
                         CDEM_OK);
        assert_int_equal(cdem_state_append(s, -1, 100.0 * n_cols + 50.0, 50.0 + 100.0 * j, 50.0,
                                           1.0, 0, CDEM_FLAG_WALL | CDEM_FLAG_MOVING, 0, NULL,
                                           &err),
                         CDEM_OK);
    }
    for (int c = -1; c <= n_cols; c++)
        assert_int_equal(cdem_state_append(s, -1, 50.0 + 100.0 * c, -50.0, 50.0, 1.0, 0,
                                           CDEM_FLAG_WALL, 0, NULL, &err),
                         CDEM_OK);
}

/* Lifts every free element of column c >= n_cols - k by u(c) = h (x_c - x_toe) / L with
 * L = 100 k and x_toe = 100 (n_cols - k): a triangular wedge of height h against the wall. */
static void lift_triangle(cdem_state *s, int n_cols, int k, double h) {
    const double L = 100.0 * k, xt = 100.0 * (n_cols - k);
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY) && s->x[i] > xt)
            s->y[i] += h * (s->x[i] - xt) / L;
}

static void test_wedge_triangle_exact(void **state) {
    (void)state;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    make_lattice(&ref, 40, 10);
    assert_int_equal(cdem_state_copy(&cur, &ref, &err), CDEM_OK);
    lift_triangle(&cur, 40, 20, 1000.0); /* L = 2000 m, H = 1000 m */
    cdem_wedge_options opt = {.threshold = 1.0};
    cdem_wedge_ref r;
    assert_int_equal(cdem_wedge_reference(&ref, &opt, &r, &err), CDEM_OK);
    assert_near(r.x_left, 0.0, 1e-9);
    assert_near(r.wall_x0, 4000.0, 1e-9);
    assert_near(r.length0, 4000.0, 1e-9);
    assert_near(r.column_width, 100.0, 1e-12);
    assert_int_equal(r.n_columns, 40);
    assert_near(r.y_base, 0.0, 1e-9);
    assert_near(r.surface0, 1000.0, 1e-9);
    assert_near(r.thickness0, 1000.0, 1e-9);
    assert_near(r.area0, 4.0e6, 1e-3);
    cdem_wedge_row row;
    assert_int_equal(cdem_wedge_measure(&r, &ref, &cur, &row, &err), CDEM_OK);
    /* the highest column centre is 50 m short of the wall: u = 1000 x 1950 / 2000 */
    assert_near(row.height, 975.0, 1e-9);
    assert_near(row.front_x, 2000.0, 1e-9);
    assert_near(row.length, 2000.0, 1e-9);
    assert_near(row.length_thickened, 2000.0, 1e-9);
    assert_near(row.taper_deg, atan(0.5) / deg, 1e-9);
    assert_int_equal(row.n_fitted, 20);
    /* midpoint sums of a linear rise are exact: the triangle's area 1/2 H L */
    assert_near(row.area_change, 0.5 * 1000.0 * 2000.0, 1e-3);
    assert_near(row.area_change_percent, 25.0, 1e-9);
    assert_near(row.wall_x, 4000.0, 1e-9);

    /* default threshold = the mean diameter (100 m): columns lifted by more than 100 m,
     * u(c) = 50 (c - 20) + 25 > 100 from c = 22 on */
    assert_int_equal(cdem_wedge_reference(&ref, NULL, &r, &err), CDEM_OK);
    assert_near(r.threshold, 100.0, 1e-12);
    assert_int_equal(cdem_wedge_measure(&r, &ref, &cur, &row, &err), CDEM_OK);
    assert_near(row.front_x, 2200.0, 1e-9);
    assert_near(row.length, 1800.0, 1e-9);
    assert_near(row.length_thickened, 1800.0, 1e-9);
    assert_near(row.taper_deg, atan(0.5) / deg, 1e-9);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

/* Columns 10..19 moved (down 200 m) without thickening: the deformed zone reaches them,
 * the thickened zone (and the taper fit) does not. */
static void test_wedge_moved_but_not_thickened(void **state) {
    (void)state;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    make_lattice(&ref, 40, 10);
    assert_int_equal(cdem_state_copy(&cur, &ref, &err), CDEM_OK);
    lift_triangle(&cur, 40, 20, 1000.0);
    for (size_t i = 0; i < cur.n; i++)
        if (!(cur.flags[i] & CDEM_FLAGS_BOUNDARY) && cur.x[i] > 1000.0 && cur.x[i] < 2000.0)
            cur.y[i] -= 200.0;
    cdem_wedge_options opt = {.threshold = 1.0};
    cdem_wedge_ref r;
    cdem_wedge_row row;
    assert_int_equal(cdem_wedge_reference(&ref, &opt, &r, &err), CDEM_OK);
    assert_int_equal(cdem_wedge_measure(&r, &ref, &cur, &row, &err), CDEM_OK);
    assert_near(row.front_x, 1000.0, 1e-9);
    assert_near(row.length, 3000.0, 1e-9);
    assert_near(row.length_thickened, 2000.0, 1e-9);
    assert_near(row.taper_deg, atan(0.5) / deg, 1e-9);
    assert_int_equal(row.n_fitted, 20);
    assert_near(row.height, 975.0, 1e-9);
    assert_near(row.area_change, 1.0e6 - 10 * 100.0 * 200.0, 1e-3);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

/* The wall face 9 m into a column, with one small element squeezed at the wall's foot in
 * that sliver (examples/wedge, every fifth increment): the sliver's top is not the wedge's
 * surface and stays out of the taper fit, which keeps the triangle's exact slope. */
static void test_wedge_taper_ignores_sliver_at_wall(void **state) {
    (void)state;
    cdem_state ref = {0}, lifted = {0}, cur = {0};
    cdem_error err;
    make_lattice(&ref, 40, 10);
    assert_int_equal(cdem_state_copy(&lifted, &ref, &err), CDEM_OK);
    lift_triangle(&lifted, 40, 20, 1000.0); /* slope 0.5 over columns 20..39 */
    /* the wall moved 991 m left: face at 3009; the free elements beyond it are gone */
    assert_int_equal(cdem_state_init(&cur, lifted.n, 0, &err), CDEM_OK);
    for (size_t i = 0; i < lifted.n; i++) {
        const uint32_t f = lifted.flags[i];
        const double x = (f & CDEM_FLAG_MOVING) ? lifted.x[i] - 991.0 : lifted.x[i];
        if (!(f & CDEM_FLAGS_BOUNDARY) && x > 3000.0)
            continue;
        assert_int_equal(cdem_state_append(&cur, lifted.id[i], x, lifted.y[i], lifted.radius[i],
                                           1.0, lifted.layer[i], f, 0, NULL, &err),
                         CDEM_OK);
    }
    assert_int_equal(cdem_state_append(&cur, -1, 3004.0, 5.0, 4.0, 1.0, 1, 0, 0, NULL, &err),
                     CDEM_OK);
    cdem_wedge_options opt = {.threshold = 1.0};
    cdem_wedge_ref r;
    cdem_wedge_row row;
    assert_int_equal(cdem_wedge_reference(&ref, &opt, &r, &err), CDEM_OK);
    assert_int_equal(cdem_wedge_measure(&r, &ref, &cur, &row, &err), CDEM_OK);
    assert_near(row.wall_x, 3009.0, 1e-9);
    assert_near(row.taper_deg, atan(0.5) / deg, 1e-9);
    assert_int_equal(row.n_fitted, 10); /* columns 20..29, not the sliver of column 30 */
    cdem_state_free(&ref);
    cdem_state_free(&lifted);
    cdem_state_free(&cur);
}

static void test_wedge_flat_state_zero(void **state) {
    (void)state;
    cdem_state ref = {0};
    cdem_error err;
    make_lattice(&ref, 30, 8);
    cdem_wedge_ref r;
    cdem_wedge_row row;
    assert_int_equal(cdem_wedge_reference(&ref, NULL, &r, &err), CDEM_OK);
    assert_int_equal(cdem_wedge_measure(&r, &ref, &ref, &row, &err), CDEM_OK);
    assert_true(row.height == 0.0);
    assert_true(row.length == 0.0 && row.length_thickened == 0.0);
    assert_true(row.area_change == 0.0);
    assert_true(isnan(row.taper_deg));
    assert_true(isnan(row.front_x));
    assert_int_equal(row.n_fitted, 0);
    cdem_state_free(&ref);
}

/* Shortening a flat layer uniformly (x scaled towards the left face, y stretched to keep
 * the area) moves every column: the whole layer is the deformed zone, the surface stays
 * flat (taper 0) and the area is conserved. */
static void test_wedge_uniform_thickening(void **state) {
    (void)state;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    make_lattice(&ref, 40, 10);
    assert_int_equal(cdem_state_copy(&cur, &ref, &err), CDEM_OK);
    const double f = 0.8; /* 20 % shortening: x -> 0.8 x, y -> y / 0.8 */
    for (size_t i = 0; i < cur.n; i++) {
        if (cur.flags[i] & CDEM_FLAG_MOVING)
            cur.x[i] -= 800.0;
        else if (!(cur.flags[i] & CDEM_FLAGS_BOUNDARY)) {
            cur.x[i] *= f;
            cur.y[i] /= f;
        }
    }
    cdem_wedge_ref r;
    cdem_wedge_row row;
    assert_int_equal(cdem_wedge_reference(&ref, NULL, &r, &err), CDEM_OK);
    assert_int_equal(cdem_wedge_measure(&r, &ref, &cur, &row, &err), CDEM_OK);
    assert_near(row.wall_x, 3200.0, 1e-9);
    assert_near(row.front_x, 0.0, 1e-9); /* every column moved: the whole layer */
    assert_near(row.length, 3200.0, 1e-9);
    assert_near(row.length_thickened, 3200.0, 1e-9);
    assert_near(row.taper_deg, 0.0, 1e-9);
    /* top row at 950 / 0.8 + 50 = 1237.5 m, 237.5 m above the initial 1000 m */
    assert_near(row.height, 237.5, 1e-9);
    /* 32 full columns of 100 m (the material's left face at -10 m is not counted) */
    assert_near(row.area_change, 32 * 100.0 * 1237.5 - 4.0e6, 1e-3);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

static void test_wedge_errors_name_the_problem(void **state) {
    (void)state;
    cdem_state s = {0};
    cdem_error err;
    make_lattice(&s, 10, 5);
    cdem_wedge_ref r;
    cdem_wedge_options bad = {.threshold = -1.0};
    assert_int_equal(cdem_wedge_reference(&s, &bad, &r, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "threshold = -1 m"));
    bad.threshold = NAN;
    assert_int_equal(cdem_wedge_reference(&s, &bad, &r, &err), CDEM_ERR_RANGE);
    for (size_t i = 0; i < s.n; i++)
        s.flags[i] &= ~(uint32_t)CDEM_FLAG_MOVING;
    assert_int_equal(cdem_wedge_reference(&s, NULL, &r, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "no moving wall"));
    assert_non_null(strstr(err.msg, "boundary.mode = detachment"));
    cdem_state empty = {0};
    assert_int_equal(cdem_state_init(&empty, 4, 0, &err), CDEM_OK);
    assert_int_equal(cdem_wedge_reference(&empty, NULL, &r, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "no free (non-wall) elements"));
    cdem_state_free(&empty);
    cdem_state_free(&s);
}

static void test_wedge_forces_mean_and_nearest(void **state) {
    (void)state;
    cdem_series_sample smp[5];
    memset(smp, 0, sizeof smp);
    for (int k = 0; k < 5; k++) {
        smp[k].step = 100 * (k + 1);
        smp[k].boundary_force_x = 10.0 * (k + 1);
        smp[k].boundary_force_y = -1.0 * (k + 1);
        smp[k].base_force_x = -3.0 * (k + 1);
        smp[k].base_force_y = -100.0 * (k + 1);
        smp[k].left_wall_force_x = -20.0 * (k + 1);
        smp[k].left_wall_force_y = 2.0 * (k + 1);
        smp[k].right_wall_force_x = 30.0 * (k + 1);
        smp[k].right_wall_force_y = NAN; /* a file from before the column */
    }
    cdem_wedge_row row;
    cdem_wedge_forces(smp, 5, 150, 400, &row); /* samples at 200, 300, 400 */
    assert_near(row.wall_force_x, 30.0, 1e-12);
    assert_near(row.wall_force_y, -3.0, 1e-12);
    assert_near(row.base_force_x, -9.0, 1e-12);
    assert_near(row.base_force_y, -300.0, 1e-12);
    assert_near(row.left_wall_force_x, -60.0, 1e-12);
    assert_near(row.left_wall_force_y, 6.0, 1e-12);
    assert_near(row.right_wall_force_x, 90.0, 1e-12);
    assert_true(isnan(row.right_wall_force_y));
    cdem_wedge_forces(smp, 5, 410, 440, &row); /* none inside: nearest (400) */
    assert_near(row.wall_force_x, 40.0, 1e-12);
    assert_near(row.right_wall_force_x, 120.0, 1e-12);
    cdem_wedge_forces(smp, 0, 0, 100, &row);
    assert_true(isnan(row.wall_force_x) && isnan(row.base_force_y));
    assert_true(isnan(row.left_wall_force_x) && isnan(row.right_wall_force_y));
}

/* The analysis path over in-memory states: rows from the end of equilibration, shortening
 * from the increment info, forces NaN without a time series. */
static void test_wedge_analyse_states(void **state) {
    (void)state;
    cdem_state st[3] = {{0}, {0}, {0}};
    cdem_error err;
    make_lattice(&st[0], 40, 10);
    assert_int_equal(cdem_state_copy(&st[1], &st[0], &err), CDEM_OK);
    assert_int_equal(cdem_state_copy(&st[2], &st[0], &err), CDEM_OK);
    lift_triangle(&st[2], 40, 20, 1000.0);
    cdem_increment_info in[3];
    memset(in, 0, sizeof in);
    for (int k = 0; k < 3; k++) {
        in[k].number = k;
        in[k].step = 1000 * k;
        in[k].phase = k < 2 ? CDEM_PHASE_EQUILIBRATION : CDEM_PHASE_DEFORMATION;
        in[k].net_displacement = k < 2 ? 0.0 : 400.0;
        in[k].n_elements = (int64_t)st[k].n;
    }
    cdem_params p;
    cdem_params_defaults(&p); /* a planar-fault run: refused */
    cdem_analysis *a;
    cdem_wedge_row *rows;
    size_t n;
    cdem_wedge_ref ref;
    cdem_wedge_options opt = {.threshold = 1.0};
    assert_int_equal(cdem_analysis_open_states(st, in, 3, &p, &a, &err), CDEM_OK);
    assert_int_equal(cdem_wedge_analyse(a, &opt, 0, 2, &rows, &n, &ref, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "'planar-fault' run"));
    assert_non_null(strstr(err.msg, "needs boundary.mode = detachment"));
    cdem_analysis_close(a);
    p.mode = CDEM_MODE_DETACHMENT;
    assert_int_equal(cdem_analysis_open_states(st, in, 3, &p, &a, &err), CDEM_OK);
    assert_int_equal(cdem_wedge_analyse(a, &opt, 0, 2, &rows, &n, &ref, &err), CDEM_OK);
    assert_int_equal(n, 2); /* increments 1 (end of equilibration) and 2 */
    assert_int_equal(rows[0].number, 1);
    assert_true(rows[0].height == 0.0 && rows[0].length == 0.0);
    assert_int_equal(rows[1].number, 2);
    assert_int_equal(rows[1].step, 2000);
    assert_near(rows[1].shortening_percent, 10.0, 1e-12);
    assert_near(rows[1].length, 2000.0, 1e-9);
    assert_true(isnan(rows[1].wall_force_x));
    free(rows);
    assert_int_equal(cdem_wedge_analyse(a, &opt, 0, 0, &rows, &n, &ref, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "before the end of equilibration"));
    cdem_analysis_close(a);
    for (int k = 0; k < 3; k++)
        cdem_state_free(&st[k]);
}

static void test_wedge_csv_round_trip(void **state) {
    (void)state;
    cdem_wedge_row rows[3];
    memset(rows, 0, sizeof rows);
    for (int k = 0; k < 3; k++) {
        rows[k] = (cdem_wedge_row){.number = 56 + k,
                                   .step = 14192 + 5035L * k,
                                   .shortening = 100.0 * k + 0.125,
                                   .shortening_percent = 1.0 / 3.0 * k,
                                   .height = 1234.5678901 * k,
                                   .length = 2000.0 + k,
                                   .length_thickened = 1500.0 - k,
                                   .taper_deg = k ? 7.25 * k : NAN,
                                   .area_change = -1.5e6 * k,
                                   .area_change_percent = -2.5 * k,
                                   .wall_force_x = 6.8356470580e11,
                                   .wall_force_y = -1e-3,
                                   .base_force_x = -3.5e11,
                                   .base_force_y = -7.7e11,
                                   .front_x = k ? 995.0 : NAN,
                                   .wall_x = 9999.9 - k,
                                   .n_fitted = (size_t)(3 * k),
                                   .left_wall_force_x = -6.5e11 * k,
                                   .left_wall_force_y = 1.25e9,
                                   .right_wall_force_x = k ? 6.6e11 : NAN,
                                   .right_wall_force_y = -2.5e9};
    }
    char path[1100];
    snprintf(path, sizeof path, "%s/wedge_rt_%d.csv", scratch_root(), (int)getpid());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    cdem_error err;
    assert_int_equal(cdem_wedge_write_csv(f, rows, 3, &err), CDEM_OK);
    fclose(f);
    cdem_csvtable t;
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_OK);
    assert_int_equal(t.n_rows, 3);
    assert_int_equal(t.n_cols, 21);
    static const char *const names[] = {"increment",
                                        "step",
                                        "shortening_m",
                                        "shortening_percent",
                                        "height_m",
                                        "length_m",
                                        "length_thickened_m",
                                        "taper_deg",
                                        "area_change_m2",
                                        "area_change_percent",
                                        "wall_force_x_N",
                                        "wall_force_y_N",
                                        "base_force_x_N",
                                        "base_force_y_N",
                                        "front_x_m",
                                        "wall_x_m",
                                        "n_fitted",
                                        "left_wall_force_x_N",
                                        "left_wall_force_y_N",
                                        "right_wall_force_x_N",
                                        "right_wall_force_y_N"};
    for (int k = 0; k < 3; k++) {
        const cdem_wedge_row *r = &rows[k];
        const double want[21] = {r->number,
                                 (double)r->step,
                                 r->shortening,
                                 r->shortening_percent,
                                 r->height,
                                 r->length,
                                 r->length_thickened,
                                 r->taper_deg,
                                 r->area_change,
                                 r->area_change_percent,
                                 r->wall_force_x,
                                 r->wall_force_y,
                                 r->base_force_x,
                                 r->base_force_y,
                                 r->front_x,
                                 r->wall_x,
                                 (double)r->n_fitted,
                                 r->left_wall_force_x,
                                 r->left_wall_force_y,
                                 r->right_wall_force_x,
                                 r->right_wall_force_y};
        for (int c = 0; c < 21; c++) {
            size_t col;
            assert_int_equal(cdem_csvtable_find(&t, names[c], path, &col, &err), CDEM_OK);
            const double got = t.values[(size_t)k * t.n_cols + col];
            if (isnan(want[c]))
                assert_true(isnan(got));
            else
                assert_near(got, want[c], 1e-9 * fmax(1.0, fabs(want[c])));
        }
    }
    size_t col;
    assert_int_equal(cdem_csvtable_find(&t, "heigth_m", path, &col, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "no column 'heigth_m'"));
    assert_non_null(strstr(err.msg, "height_m"));
    cdem_csvtable_free(&t);
    cdem_csvtable_free(NULL);
    /* a malformed line is named by file, line, column and text */
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("a,b\n1,2\n# comment\n3,x7\n", f);
    fclose(f);
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, ":4: column 2 (b): 'x7' is not a number"));
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("a,b\n1,2,3\n", f);
    fclose(f);
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, "too many fields"));
    f = fopen(path, "w");
    assert_non_null(f);
    fclose(f);
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, "empty file"));
    f = fopen(path, "wb");
    assert_non_null(f);
    fputs("\x89HDF\r\n\x1a\n", f);
    fclose(f);
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, "not text (binary data?)"));
    remove(path);
    assert_int_equal(cdem_csvtable_read(path, &t, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "cannot open"));
}

static int run(const char *cmd, char *out, size_t n) {
    char full[8192];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    if (!p)
        return -1;
    size_t got = fread(out, 1, n - 1, p);
    out[got] = '\0';
    while (fread(full, 1, sizeof full, p) > 0) {
    }
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* A 10 x 2.5 km detachment run, 100 s of shortening (70 m): the wedge command's CSV, the
 * recorded forces (the wall pushes, the base carries the weight) and plot-csv's PNG. */
static void test_wedge_end_to_end_detachment(void **state) {
    (void)state;
    const char *b = getenv("CDEM_BUILD");
    char *bin = realpath(b ? b : "build", NULL);
    assert_non_null(bin);
    char dir[1100], cmd[4096], out[8192];
    snprintf(dir, sizeof dir, "%s/wedge_e2e_%d", scratch_root(), (int)getpid());
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-run' -q -s boundary.mode=detachment -s assembly.height=2.5 "
             "-s time.equilibration=200 -s time.runtime=300 -s time.display_interval=20 "
             "-s material.wall_cohesion=0 -s material.wall_friction=0 -o '%s/run.h5'",
             bin, dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' wedge '%s/run.h5' -o '%s/w.csv'", bin, dir, dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "cdem-strain wedge: reference increment"));
    char csv[1200];
    snprintf(csv, sizeof csv, "%s/w.csv", dir);
    cdem_csvtable t;
    cdem_error err;
    assert_int_equal(cdem_csvtable_read(csv, &t, &err), CDEM_OK);
    assert_true(t.n_rows >= 4);
    size_t c_sh, c_wx, c_by, c_area, c_h;
    assert_int_equal(cdem_csvtable_find(&t, "shortening_m", csv, &c_sh, &err), CDEM_OK);
    assert_int_equal(cdem_csvtable_find(&t, "wall_force_x_N", csv, &c_wx, &err), CDEM_OK);
    assert_int_equal(cdem_csvtable_find(&t, "base_force_y_N", csv, &c_by, &err), CDEM_OK);
    assert_int_equal(cdem_csvtable_find(&t, "area_change_percent", csv, &c_area, &err), CDEM_OK);
    assert_int_equal(cdem_csvtable_find(&t, "height_m", csv, &c_h, &err), CDEM_OK);
    const size_t nc = t.n_cols, last = t.n_rows - 1;
    assert_true(t.values[c_sh] == 0.0);                  /* the reference row */
    assert_near(t.values[last * nc + c_sh], 70.46, 0.5); /* 100 s x 0.7046 m/s */
    assert_true(t.values[c_h] == 0.0);
    /* frictionless walls: the base carries the whole weight of the layer, W = sum of
     * 2500 kg/m^3 x pi r^2 x 9.81 m/s^2 over the free elements */
    char h5[1200];
    snprintf(h5, sizeof h5, "%s/run.h5", dir);
    cdem_h5_reader *rd;
    assert_int_equal(cdem_h5_reader_open(h5, &rd, &err), CDEM_OK);
    cdem_state s0 = {0};
    cdem_increment_info info;
    assert_int_equal(cdem_h5_reader_load_increment(rd, 0, &s0, &info, &err), CDEM_OK);
    double weight = 0.0;
    for (size_t i = 0; i < s0.n; i++)
        if (!(s0.flags[i] & CDEM_FLAGS_BOUNDARY))
            weight += 2500.0 * 3.14159265358979323846 * s0.radius[i] * s0.radius[i] * 9.81;
    cdem_state_free(&s0);
    cdem_h5_reader_close(rd);
    assert_true(weight > 3e11 && weight < 6e11); /* about 20 km^2 of solid */
    for (size_t k = 0; k <= last; k++) {
        if (k > 0)
            assert_true(t.values[k * nc + c_wx] > 1e9); /* the wall pushes the material */
        assert_near(t.values[k * nc + c_by], -weight, 0.02 * weight);
        assert_true(fabs(t.values[k * nc + c_area]) < 3.0);
    }
    cdem_csvtable_free(&t);
    /* plot-csv: two files on one figure; PNG signature */
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-strain' plot-csv '%s/w.csv' '%s/w.csv' --labels a,b --x shortening_m "
             "--y height_m,wall_force_x_N,base_force_y_N --columns 2 -o '%s/f.png'",
             bin, dir, dir, dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    char png[1200];
    snprintf(png, sizeof png, "%s/f.png", dir);
    FILE *f = fopen(png, "rb");
    assert_non_null(f);
    unsigned char sig[8] = {0};
    assert_int_equal(fread(sig, 1, 8, f), 8);
    fclose(f);
    assert_memory_equal(sig, "\x89PNG\r\n\x1a\n", 8);
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-strain' plot-csv '%s/w.csv' --x shortening_m --y height_m --legend 0 "
             "-o '%s/g.svg'",
             bin, dir, dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-strain' plot-csv '%s/w.csv' --x shortening_m --y height_m --legend 17 "
             "-o '%s/g.svg'",
             bin, dir, dir);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "--legend must be a panel number"));
    /* usage and column errors */
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-strain' plot-csv '%s/w.csv' --x shortening_m --y nope -o '%s/g.png'", bin,
             dir, dir);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "no column 'nope'"));
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-strain' plot-csv '%s/w.csv' --labels a,b --x shortening_m --y height_m "
             "-o '%s/g.png'",
             bin, dir, dir);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "one label per CSV file"));
    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' wedge '%s/run.h5' --threshold -3", bin, dir);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "--threshold must be a length"));
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
    free(bin);
}

/* A non-detachment run (no moving wall right of the material) is refused by name. */
static void test_wedge_refuses_a_run_without_moving_wall(void **state) {
    (void)state;
    cdem_state s = {0};
    cdem_error err;
    make_lattice(&s, 10, 5);
    for (size_t i = 0; i < s.n; i++)
        if (s.flags[i] & CDEM_FLAG_MOVING)
            s.x[i] = -500.0; /* a moving wall left of the material is not the right wall */
    cdem_wedge_ref r;
    assert_int_equal(cdem_wedge_reference(&s, NULL, &r, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "right of the material's middle"));
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wedge_triangle_exact),
        cmocka_unit_test(test_wedge_moved_but_not_thickened),
        cmocka_unit_test(test_wedge_taper_ignores_sliver_at_wall),
        cmocka_unit_test(test_wedge_flat_state_zero),
        cmocka_unit_test(test_wedge_uniform_thickening),
        cmocka_unit_test(test_wedge_errors_name_the_problem),
        cmocka_unit_test(test_wedge_forces_mean_and_nearest),
        cmocka_unit_test(test_wedge_analyse_states),
        cmocka_unit_test(test_wedge_csv_round_trip),
        cmocka_unit_test(test_wedge_end_to_end_detachment),
        cmocka_unit_test(test_wedge_refuses_a_run_without_moving_wall),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
