/* Tests of solver/bc_registry + bc_planar_fault: hanging-wall kinematics (exact
 * displacement along the dip), fixed footwall, inversion, net displacement, no escapes,
 * and the registry's errors for unimplemented modes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "bc_fixtures.h"
#include "integrate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define KN  1.544871985e9
#define RHO 2500.0
#define DT  0.028

/* The shared fixture parameters, as a planar normal fault dipping 60 degrees. */
static cdem_params hand_params(void) {
    cdem_params p = fx_params(CDEM_MODE_PLANAR_FAULT);
    p.first_slip = 0;
    p.fault_sense = CDEM_SENSE_NORMAL;
    p.fault_location = 0.5;
    p.fault_dip = 60.0;
    return p;
}

typedef struct {
    long steps;     /* deformation steps run */
    double net_mid; /* net displacement after half the steps */
    double net_end; /* net displacement at the end */
    cdem_state s0;  /* the state after init (before motion) */
    cdem_state s;   /* the final state */
    long removed;   /* elements removed as escaped */
    long ramp_fixed, ramp_moving;
} run_result;

static void run_fault(cdem_params p, long steps, run_result *out) {
    cdem_model m = fx_model(steps);
    cdem_error err;
    cdem_bc bc;
    cdem_integrator it;
    memset(out, 0, sizeof *out);
    fx_assembly(&out->s);
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &out->s, &err), CDEM_OK);
    for (size_t i = 0; i < out->s.n; i++) {
        if ((out->s.flags[i] & CDEM_FLAG_FAULT) && (out->s.flags[i] & CDEM_FLAG_MOVING))
            out->ramp_moving++;
        else if (out->s.flags[i] & CDEM_FLAG_FAULT)
            out->ramp_fixed++;
    }
    assert_int_equal(cdem_state_copy(&out->s0, &out->s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    cdem_integrator_enable_escape(&it);
    for (long k = 1; k <= steps; k++) {
        assert_int_equal(cdem_integrator_step(&it, &out->s, &bc, k, m.displacement_per_step, &err),
                         CDEM_OK);
        if (k == steps / 2)
            out->net_mid = cdem_bc_net_displacement(&bc);
    }
    out->steps = steps;
    out->removed = it.removal.n_removed;
    out->net_end = cdem_bc_net_displacement(&bc);
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
}

/* Displacement of element id between s0 and s (the state may be re-sorted). */
static void displacement_of(const cdem_state *s0, const cdem_state *s, int32_t id, double *dx,
                            double *dy) {
    size_t a = SIZE_MAX, b = SIZE_MAX;
    for (size_t i = 0; i < s0->n; i++)
        if (s0->id[i] == id)
            a = i;
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == id)
            b = i;
    assert_true(a != SIZE_MAX && b != SIZE_MAX);
    *dx = s->x[b] - s0->x[a];
    *dy = s->y[b] - s0->y[a];
}

static void test_bc_planar_normal_kinematics(void **st) {
    (void)st;
    run_result r;
    const long K = 600;
    cdem_params p = hand_params();
    run_fault(p, K, &r);
    const double d = 60.0 * M_PI / 180.0;
    const double u = (double)K * CDEM_BOUNDARY_ACCEL * DT * DT;
    long n_hw = 0, n_fw = 0;
    assert_true(r.ramp_fixed > 0);
    assert_int_equal(r.ramp_moving, 0);
    for (size_t i = 0; i < r.s0.n; i++) {
        const uint32_t f = r.s0.flags[i];
        if (!(f & (CDEM_FLAG_WALL | CDEM_FLAG_FAULT)))
            continue;
        double dx, dy;
        displacement_of(&r.s0, &r.s, r.s0.id[i], &dx, &dy);
        if (f & CDEM_FLAG_MOVING) {
            /* hanging wall: base right of x = 2000 m and the right wall */
            assert_true(r.s0.x[i] > 2000.0);
            assert_float_equal(dx, u * cos(d), 1e-9 * u);
            assert_float_equal(dy, -u * sin(d), 1e-9 * u);
            n_hw++;
        } else {
            assert_true(dx == 0.0 && dy == 0.0); /* footwall walls and fixed ramp never move */
            if ((f & CDEM_FLAG_WALL) && r.s0.y[i] == 0.0)
                assert_true(r.s0.x[i] <= 2000.0); /* footwall base */
            n_fw++;
        }
    }
    assert_true(n_hw > 20 && n_fw > 20);
    assert_int_equal(r.removed, 0);
    assert_int_equal(r.s.n, r.s0.n);
    /* the fixed ramp lies along the fault plane, below the base, dipping toward +x */
    for (size_t i = 0; i < r.s0.n; i++)
        if (r.s0.flags[i] & CDEM_FLAG_FAULT) {
            double sx = r.s0.x[i] - 2000.0, sy = -r.s0.y[i];
            assert_true(sx > 0.0 && sy > 0.0);
            assert_float_equal(atan2(sy, sx), d, 1e-9);
        }
    assert_float_equal(r.net_mid, (K / 2) * CDEM_BOUNDARY_ACCEL * DT * DT, 1e-9);
    assert_float_equal(r.net_end, u, 1e-9);
    cdem_state_free(&r.s0);
    cdem_state_free(&r.s);
}

static void test_bc_planar_reverse_inversion(void **st) {
    (void)st;
    run_result r;
    const long K = 600;
    cdem_params p = hand_params();
    p.fault_sense = CDEM_SENSE_REVERSE;
    p.inversion = 1;
    p.inversion_percent = 50.0;
    run_fault(p, K, &r);
    const double dps = CDEM_BOUNDARY_ACCEL * DT * DT;
    /* reverse for the first half (up-dip), then normal back to the start: net 0 */
    assert_float_equal(r.net_mid, (K / 2) * dps, 1e-9);
    assert_float_equal(r.net_end, 0.0, 1e-9);
    assert_true(r.ramp_fixed > 0 && r.ramp_moving > 0); /* both senses need their ramp */
    for (size_t i = 0; i < r.s0.n; i++) {
        if (!(r.s0.flags[i] & CDEM_FLAG_MOVING))
            continue;
        double dx, dy;
        displacement_of(&r.s0, &r.s, r.s0.id[i], &dx, &dy);
        assert_float_equal(dx, 0.0, 1e-9);
        assert_float_equal(dy, 0.0, 1e-9);
    }
    assert_int_equal(r.removed, 0);
    cdem_state_free(&r.s0);
    cdem_state_free(&r.s);

    /* inversion at 25 %: reverse 150 steps, then normal 450: net -300 steps down-dip */
    p.inversion_percent = 25.0;
    run_fault(p, K, &r);
    const double d = 60.0 * M_PI / 180.0;
    for (size_t i = 0; i < r.s0.n; i++) {
        if (!(r.s0.flags[i] & CDEM_FLAG_MOVING))
            continue;
        double dx, dy;
        displacement_of(&r.s0, &r.s, r.s0.id[i], &dx, &dy);
        /* initial sense reverse = (-cos, +sin); net = 150 - 450 = -300 steps of it */
        assert_float_equal(dx, 300.0 * dps * cos(d), 1e-9);
        assert_float_equal(dy, -300.0 * dps * sin(d), 1e-9);
    }
    assert_float_equal(r.net_end, -300.0 * dps, 1e-9);
    cdem_state_free(&r.s0);
    cdem_state_free(&r.s);
}

static void test_bc_planar_registry_errors(void **st) {
    (void)st;
    cdem_params p = hand_params();
    cdem_model m = fx_model(100);
    cdem_error err;
    cdem_bc bc;
    cdem_state s;
    fx_assembly(&s);
    p.mode = (cdem_mode)42;
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "42"));
    p = hand_params();
    p.fault_dip = 95.0;
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "fault_dip = 95"));
    p = hand_params();
    const cdem_bc_ops *ops = NULL;
    assert_int_equal(cdem_bc_find(CDEM_MODE_PLANAR_FAULT, &ops, &err), CDEM_OK);
    /* an assembly without walls has no base to split */
    cdem_state bare;
    assert_int_equal(cdem_state_init(&bare, 4, 0, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&bare, -1, 0, 0, 50, 1, 1, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &bare, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "no wall elements"));
    /* view describes the effective settings; the instance knows its mode's word */
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_OK);
    assert_string_equal(bc.name, "planar-fault");
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    cdem_bc_view(&bc, f);
    fclose(f);
    assert_non_null(strstr(buf, "planar normal fault"));
    assert_non_null(strstr(buf, "dip 60.0"));
    assert_non_null(strstr(buf, "x = 2000.0 m"));
    free(buf);
    cdem_bc_free(&bc);
    cdem_bc_free(&bc);
    cdem_bc_free(NULL);
    cdem_state_free(&bare);
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_planar_normal_kinematics),
        cmocka_unit_test(test_bc_planar_reverse_inversion),
        cmocka_unit_test(test_bc_planar_registry_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
