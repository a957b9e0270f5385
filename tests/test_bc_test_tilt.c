/* Gravity as a vector (issue 45, item 4), through the tests' mode fixture
 * solver/modes/bc_test_tilt.c: gravity tilted 2 degrees toward +x from the start (its derive),
 * turning 1 degree more over the deformation steps (its gravity hook). Its walls never move.
 *   tilt-1: at rest after equilibration, the walls carry the assembly's weight along the
 *           tilted vertical: the sum of the forces on the wall elements points 2 degrees from
 *           -y toward +x and equals the free elements' weight (statics, no fit).
 *   tilt-2: the summary states the tilt and the vector; the vector helper gives exactly
 *           (0, -g) untilted and keeps g's magnitude tilted.
 *   tilt-3: a run resumed from a mid-deformation checkpoint (taken while gravity turns) ends
 *           bit-identical to the uninterrupted run, gravity's last direction included.
 *   tilt-4: the scalar and the vector force paths (CDEM_SIMD) give the same bits with a
 *           tilted gravity, as they do without. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "run.h"
#include "run_fixtures.h"
#include "snapshot.h"
#include "state.h"
#include "summary.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A small default model in the fixture mode (no file, no checkpoints written). */
static cdem_params tilt_params(void) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_TEST_TILT;
    p.height = 2.5;
    p.equilibration = 200;
    p.runtime = 300;
    p.checkpoint_interval = 0;
    return p;
}

/* tilt-1 */
static void test_bc_test_tilt_walls_carry_the_tilted_weight(void **state) {
    (void)state;
    const cdem_params p = tilt_params();
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_run_ctx *r = open_run(&p, NULL);
    /* the end of equilibration, rounded down to a series sample (boundary forces current) */
    const long at = m.equil_steps / p.series_interval * p.series_interval;
    assert_int_equal(cdem_run_advance(r, at, &err), CDEM_OK);
    cdem_snapshot *snap = capture(r);
    const cdem_snapshot_array *na = cdem_snapshot_get(snap, "state.flags");
    assert_non_null(na);
    const uint32_t *flags = (const uint32_t *)na->data;
    const double *fx = array_of(snap, "state.fx"), *fy = array_of(snap, "state.fy");
    const double *mass = array_of(snap, "state.mass"), *vx = array_of(snap, "state.vx"),
                 *vy = array_of(snap, "state.vy");
    /* Newton for the free elements at rest (accelerations negligible): the walls carry their
     * weight M (gx, gy), less the drag -c v of the pile's creep (absolute damping in the
     * equilibration) */
    double gx, gy;
    cdem_model_gravity_vector(m.gravity, 2.0, &gx, &gy);
    double wall_x = 0.0, wall_y = 0.0, load_x = 0.0, load_y = 0.0, drag = 0.0, weight = 0.0;
    for (size_t i = 0; i < na->count; i++) {
        if (flags[i] & CDEM_FLAGS_BOUNDARY) {
            wall_x += fx[i];
            wall_y += fy[i];
        } else {
            load_x += mass[i] * gx - m.damping * vx[i];
            load_y += mass[i] * gy - m.damping * vy[i];
            drag += m.damping * hypot(vx[i], vy[i]);
            weight += mass[i] * m.gravity;
        }
    }
    const double angle = atan2(wall_x, -wall_y) * 180.0 / M_PI;
    const double expected = atan2(load_x, -load_y) * 180.0 / M_PI;
    if (fabs(angle - expected) > 0.05 ||
        fabs(hypot(wall_x, wall_y) / hypot(load_x, load_y) - 1.0) > 0.01)
        fail_msg("the walls carry %.6g N/m at %.4f degrees from -y; the weight less the drag is "
                 "%.6g N/m at %.4f degrees",
                 hypot(wall_x, wall_y), angle, hypot(load_x, load_y), expected);
    cdem_snapshot_free(snap);
    assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
}

/* tilt-2 */
static void test_bc_test_tilt_summary_and_vector(void **state) {
    (void)state;
    double gx = 1.0, gy = 1.0;
    cdem_model_gravity_vector(9.81, 0.0, &gx, &gy);
    assert_true(gx == 0.0 && !signbit(gx) && gy == -9.81); /* the bits of a scalar gravity */
    cdem_model_gravity_vector(9.81, 30.0, &gx, &gy);
    assert_true(fabs(hypot(gx, gy) - 9.81) < 1e-12);
    assert_true(fabs(gx - 9.81 * 0.5) < 1e-12 && gy < 0.0);
    const cdem_params p = tilt_params();
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    assert_true(m.mode.gravity_tilt == 2.0);
    char *text = NULL;
    assert_int_equal(cdem_summary_text(&p, &m, 100, 10, 1, &text, &err), CDEM_OK);
    if (!strstr(text, "9.81 m/s^2, tilted 2 degrees from -y toward +x: (0.342364, -9.80402)"))
        fail_msg("the summary's gravity line: %s",
                 strstr(text, "gravity") ? strstr(text, "gravity") : text);
    free(text);
    /* a mode that tilts gravity past the vertical is refused */
    cdem_model_mode mode = cdem_model_mode_default();
    mode.gravity_tilt = 95.0;
    assert_int_equal(cdem_model_derive(&p, &mode, &m, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "tilts gravity by 95 degrees: must be within (-90, 90)"));
}

/* tilt-3 */
static void test_bc_test_tilt_resumed_bit_identical(void **state) {
    (void)state;
    const cdem_params p = tilt_params();
    cdem_error err;
    cdem_run_ctx *straight = open_run(&p, NULL);
    const long total = cdem_run_total_steps(straight);
    assert_int_equal(cdem_run_advance(straight, total, &err), CDEM_OK);
    cdem_snapshot *end_straight = capture(straight);
    assert_int_equal(cdem_run_close(straight, CDEM_OK, &err), CDEM_OK);

    cdem_run_ctx *first = open_run(&p, NULL);
    cdem_model m;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    const long mid = m.equil_steps + (total - m.equil_steps) / 2 + 7; /* gravity is turning */
    assert_int_equal(cdem_run_advance(first, mid, &err), CDEM_OK);
    cdem_snapshot *at_mid = capture(first);
    const double gx_mid = array_of(at_mid, "it.gravity_x")[0];
    assert_int_equal(cdem_run_close(first, CDEM_OK, &err), CDEM_OK); /* the "kill" */
    /* turned past its start by about half its turn: 2.5 degrees */
    assert_true(fabs(asin(gx_mid / m.gravity) * 180.0 / M_PI - 2.5) < 0.01);

    cdem_run_ctx *resumed = open_run(&p, at_mid);
    assert_int_equal(cdem_run_current_step(resumed), mid);
    assert_int_equal(cdem_run_advance(resumed, total, &err), CDEM_OK);
    cdem_snapshot *end_resumed = capture(resumed);
    assert_int_equal(cdem_run_close(resumed, CDEM_OK, &err), CDEM_OK);
    const char *diff = NULL;
    if (!cdem_snapshot_equal(end_straight, end_resumed, &diff))
        fail_msg("the resumed run differs from the straight one at %s", diff ? diff : "?");
    /* gravity's last direction: 3 degrees */
    const double gx_end = array_of(end_resumed, "it.gravity_x")[0];
    assert_true(fabs(asin(gx_end / m.gravity) * 180.0 / M_PI - 3.0) < 1e-9);
    cdem_snapshot_free(at_mid);
    cdem_snapshot_free(end_straight);
    cdem_snapshot_free(end_resumed);
}

/* The run to its end on the force path CDEM_SIMD = path. */
static cdem_snapshot *run_on_path(const cdem_params *p, const char *path) {
    setenv("CDEM_SIMD", path, 1);
    cdem_error err;
    cdem_run_ctx *r = open_run(p, NULL);
    assert_int_equal(cdem_run_advance(r, cdem_run_total_steps(r), &err), CDEM_OK);
    cdem_snapshot *end = capture(r);
    assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
    return end;
}

/* tilt-4 */
static void test_bc_test_tilt_paths_agree(void **state) {
    (void)state;
    const cdem_params p = tilt_params();
    const char *saved = getenv("CDEM_SIMD");
    char keep[32] = "";
    if (saved)
        snprintf(keep, sizeof keep, "%s", saved);
    cdem_snapshot *scalar = run_on_path(&p, "scalar");
    const char *paths[] = {"avx2", "avx512"};
    for (int k = 0; k < 2; k++) {
        cdem_snapshot *vec = run_on_path(&p, paths[k]);
        const char *diff = NULL;
        if (!cdem_snapshot_equal(scalar, vec, &diff))
            fail_msg("CDEM_SIMD=%s differs from scalar at %s", paths[k], diff ? diff : "?");
        cdem_snapshot_free(vec);
    }
    cdem_snapshot_free(scalar);
    if (saved)
        setenv("CDEM_SIMD", keep, 1);
    else
        unsetenv("CDEM_SIMD");
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_test_tilt_walls_carry_the_tilted_weight),
        cmocka_unit_test(test_bc_test_tilt_summary_and_vector),
        cmocka_unit_test(test_bc_test_tilt_resumed_bit_identical),
        cmocka_unit_test(test_bc_test_tilt_paths_agree),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
