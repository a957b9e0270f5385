/* Tests of solver/bc_vertical_faults: the block between the faults moves exactly
 * k x displacement_per_step down (caldera) or up (piston), every other wall stays put, the
 * fault columns sit below the base at the two faults (fixed or moving with the block), net
 * displacement is the block's, and bad fault positions fail with messages naming the key. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc_fixtures.h"

#include <stdio.h>
#include <stdlib.h>

#define X1 1400.0 /* 0.35 x 4000 */
#define X2 2600.0 /* (0.35 + 0.3) x 4000 */

static void check_kinematics(cdem_vertical_sense sense) {
    const long K = 600;
    cdem_params p = fx_params(CDEM_MODE_VERTICAL_FAULTS);
    p.vertical_sense = sense;
    fx_result r;
    fx_run(p, K, &r);
    const double u = (double)K * DPS;
    const double sgn = sense == CDEM_VERT_CALDERA ? -1.0 : 1.0;
    long n_block = 0, n_fixed = 0, n_col = 0;
    for (size_t i = 0; i < r.s0.n; i++) {
        const uint32_t f = r.s0.flags[i];
        if (!(f & (CDEM_FLAG_WALL | CDEM_FLAG_FAULT)))
            continue;
        double dx, dy;
        fx_displacement(&r.s0, &r.s, r.s0.id[i], &dx, &dy);
        if (f & CDEM_FLAG_FAULT) {
            /* columns: vertical, below the base, at exactly x1 or x2 */
            assert_true(fabs(r.s0.x[i] - X1) < 1e-9 || fabs(r.s0.x[i] - X2) < 1e-9);
            assert_true(r.s0.y[i] < 0.0);
            assert_int_equal((f & CDEM_FLAG_MOVING) != 0, sense == CDEM_VERT_PISTON);
            n_col++;
        }
        if (f & CDEM_FLAG_MOVING) {
            if (f & CDEM_FLAG_WALL) {
                assert_true(r.s0.y[i] == 0.0 && r.s0.x[i] > X1 && r.s0.x[i] < X2);
                n_block++;
            }
            assert_true(dx == 0.0);
            assert_float_equal(dy, sgn * u, 1e-9 * u);
        } else {
            assert_true(dx == 0.0 && dy == 0.0); /* outside base, lateral walls, fixed columns */
            if ((f & CDEM_FLAG_WALL) && r.s0.y[i] == 0.0)
                assert_true(r.s0.x[i] <= X1 || r.s0.x[i] >= X2);
            n_fixed++;
        }
    }
    assert_int_equal(n_block, 11); /* base elements at x = 1500 .. 2500 */
    /* each column spans the whole displacement plus 4 radii, one radius apart */
    const long per_col = (long)ceil((u + 4.0 * RW) / RW);
    assert_int_equal(n_col, 2 * per_col);
    assert_true(n_fixed > 50);
    assert_float_equal(r.net_mid, (double)(K / 2) * DPS, 1e-9);
    assert_float_equal(r.net_end, u, 1e-9);
    assert_int_equal(r.removed, 0);
    fx_result_free(&r);
}

static void test_bc_vertical_caldera_kinematics(void **st) {
    (void)st;
    check_kinematics(CDEM_VERT_CALDERA);
}

static void test_bc_vertical_piston_kinematics(void **st) {
    (void)st;
    check_kinematics(CDEM_VERT_PISTON);
}

static void test_bc_vertical_errors_and_view(void **st) {
    (void)st;
    cdem_model m = fx_model(100);
    cdem_error err;
    cdem_bc bc;
    cdem_state s;
    fx_assembly(&s);
    cdem_params p = fx_params(CDEM_MODE_VERTICAL_FAULTS);
    p.vertical_fault_spacing = 0.7; /* second fault beyond the base */
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "vertical_fault_spacing = 0.7"));
    p = fx_params(CDEM_MODE_VERTICAL_FAULTS);
    p.vertical_fault_location = 0.0;
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "vertical_fault_location = 0"));
    p = fx_params(CDEM_MODE_VERTICAL_FAULTS);
    p.vertical_fault_spacing = 0.01; /* 40 m: no base element between the faults */
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "no base element"));
    p = fx_params(CDEM_MODE_VERTICAL_FAULTS);
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_OK);
    char *v = fx_view(&bc);
    assert_non_null(strstr(v, "x = 1400.0 m and x = 2600.0 m"));
    assert_non_null(strstr(v, "caldera"));
    free(v);
    const cdem_bc_ops *ops = NULL;
    assert_int_equal(cdem_bc_find(CDEM_MODE_VERTICAL_FAULTS, &ops, &err), CDEM_OK);
    assert_string_equal(cdem_mode_name(CDEM_MODE_VERTICAL_FAULTS), "vertical-faults");
    cdem_bc_free(&bc);
    cdem_state_free(&s);
}

/* Both senses run through cdem_run on a small default model; the file reports the net
 * displacement of the block. */
static void test_bc_vertical_cdem_run(void **st) {
    (void)st;
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_VERTICAL_FAULTS;
    for (int k = 0; k < 2; k++) {
        p.vertical_sense = k == 0 ? CDEM_VERT_CALDERA : CDEM_VERT_PISTON;
        cdem_increment_info last;
        cdem_model m;
        fx_cdem_run(p, "test_bc_vertical_run", 300, &last, &m);
        assert_int_equal(last.step, m.equil_steps + 300);
        assert_int_equal(last.phase, CDEM_PHASE_DEFORMATION);
        assert_float_equal(last.net_displacement, 300.0 * m.displacement_per_step, 1e-9);
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_vertical_caldera_kinematics),
        cmocka_unit_test(test_bc_vertical_piston_kinematics),
        cmocka_unit_test(test_bc_vertical_errors_and_view),
        cmocka_unit_test(test_bc_vertical_cdem_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
