/* Tests of solver/stress: Love-Weber stress against the closed form for a compressed pair
 * (axis-aligned and rotated), sign convention (compression positive), a stretched bond
 * (tension negative), and an error when the pair list does not match the state. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "integrate.h"
#include "stress.h"

#include <math.h>
#include <string.h>

#define KN 1.0e9

static cdem_model hand_model(void) {
    cdem_model m;
    memset(&m, 0, sizeof m);
    const double r[4] = {50.0, 75.0, 100.0, 125.0};
    for (int k = 0; k < 4; k++)
        m.radius[k] = r[k];
    m.max_radius = 125.0;
    m.kn = m.ks = KN;
    m.dt = 0.01;
    return m;
}

static cdem_params hand_params(cdem_material_model model) {
    cdem_params p;
    memset(&p, 0, sizeof p);
    p.material = model;
    p.element = (cdem_contact_material){.friction = 0.5, .cohesion = 0.0, .breaking_strain = 0.5};
    p.wall = p.element;
    p.fault = p.element;
    p.base = p.element;
    return p;
}

/* Two elements of radius r at angle theta, overlapping by delta; returns the stress of the
 * first in out[3] (sxx, syy, sxy). */
static void pair_stress(cdem_material_model model, double r, double delta, double theta, int bond,
                        double *out) {
    cdem_model m = hand_model();
    cdem_params p = hand_params(model);
    cdem_state s;
    cdem_error err;
    cdem_integrator it;
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    const double d = 2.0 * r - delta;
    assert_int_equal(cdem_state_append(&s, -1, 0, 0, r, 1e6, 1, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, d * cos(theta), d * sin(theta), r, 1e6, 1, 0, 0, NULL, &err),
        CDEM_OK);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    if (bond) {
        /* bond at contact, then stretch */
        s.x[1] = (2.0 * r - 1.0) * cos(theta);
        s.y[1] = (2.0 * r - 1.0) * sin(theta);
        assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
        assert_int_equal(cdem_integrator_make_cohesive(&it, &s), 1);
        s.x[1] = d * cos(theta);
        s.y[1] = d * sin(theta);
        assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    } else {
        assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    }
    assert_int_equal(cdem_stress_compute(&it.nb, &s, &err), CDEM_OK);
    assert_true(s.has_stress);
    size_t i0 = s.id[0] == 0 ? 0 : 1;
    out[0] = s.sxx[i0];
    out[1] = s.syy[i0];
    out[2] = s.sxy[i0];
    /* the partner has the same stress (equal radii, opposite branch and force) */
    assert_float_equal(s.sxx[1 - i0], out[0], 1e-9 * fabs(out[0]) + 1e-9);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

static void test_stress_compressed_pair(void **st) {
    (void)st;
    const double r = 100.0, delta = 2.0;
    double sg[3];
    pair_stress(CDEM_MATERIAL_GRANULAR, r, delta, 0.0, 0, sg);
    /* |b| = r - delta/2, |f| = Kn delta, area pi r^2; compression positive */
    const double expect = (r - 0.5 * delta) * KN * delta / (M_PI * r * r);
    assert_float_equal(sg[0], expect, 1e-9 * expect);
    assert_float_equal(sg[1], 0.0, 1e-9 * expect);
    assert_float_equal(sg[2], 0.0, 1e-9 * expect);
    /* rotated by theta: sigma = expect * (c^2, s^2, c s) */
    const double th = 0.7, c = cos(th), s = sin(th);
    pair_stress(CDEM_MATERIAL_GRANULAR, r, delta, th, 0, sg);
    assert_float_equal(sg[0], expect * c * c, 1e-9 * expect);
    assert_float_equal(sg[1], expect * s * s, 1e-9 * expect);
    assert_float_equal(sg[2], expect * c * s, 1e-9 * expect);
    /* trace is rotation-invariant */
    assert_float_equal(sg[0] + sg[1], expect, 1e-9 * expect);
}

static void test_stress_stretched_bond_is_tension(void **st) {
    (void)st;
    const double r = 100.0, stretch = 3.0;
    double sg[3];
    pair_stress(CDEM_MATERIAL_BONDED, r, -stretch, 0.0, 1, sg);
    const double expect = -(r + 0.5 * stretch) * KN * stretch / (M_PI * r * r);
    assert_float_equal(sg[0], expect, 1e-9 * fabs(expect));
    assert_true(sg[0] < 0.0);
}

static void test_stress_rejects_stale_list(void **st) {
    (void)st;
    cdem_neighbour nb;
    cdem_error err;
    cdem_state s;
    assert_int_equal(cdem_neighbour_init(&nb, 1.0, 1.0, 5, &err), CDEM_OK);
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 0, 0, 1, 1, 1, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_stress_compute(&nb, &s, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "does not match the state"));
    cdem_neighbour_free(&nb);
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stress_compressed_pair),
        cmocka_unit_test(test_stress_stretched_bond_is_tension),
        cmocka_unit_test(test_stress_rejects_stale_list),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
