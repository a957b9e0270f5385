/* Tests of solver/base/model.c: derived constants against hand-computed numbers, the boundary
 * speed relation against the paper's worked examples, the increment schedule. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "model.h"
#include "params.h"

#include <math.h>
#include <string.h>

#define REL(a, b, tol) assert_true(fabs((a) - (b)) <= (tol)*fabs(b))

static cdem_model derive(const cdem_params *p) {
    cdem_model m;
    cdem_error err;
    cdem_error_clear(&err);
    cdem_status st = cdem_bc_derive_model(p, &m, &err);
    if (st != CDEM_OK)
        print_error("%s\n", err.msg);
    assert_int_equal(st, CDEM_OK);
    return m;
}

static void test_model_default_constants_1000m(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_model m = derive(&p);
    /* radii 0.05..0.125 units x 1000 m */
    assert_true(m.radius[0] == 50.0 && m.radius[1] == 75.0 && m.radius[2] == 100.0 &&
                m.radius[3] == 125.0);
    assert_true(m.average_radius == 87.5 && m.max_radius == 125.0);
    /* min mass = 2500 kg/m^3 x pi x 50^2 m^2 = 6.25e6 pi = 19634954.0849 kg */
    REL(m.min_mass, 19634954.08493621, 1e-12);
    REL(m.mass[3], 2500.0 * M_PI * 125.0 * 125.0, 1e-12);
    /* Kn = Ks = 1544871985 N/m (unit scaling 1000 m) */
    assert_true(m.kn == 1544871985.0 && m.ks == 1544871985.0);
    /* dt = 0.25 sqrt(19634954.0849 / 1544871985) = 0.25 sqrt(0.0127098) = 0.0281844 s */
    REL(m.dt, 0.028184394225760162, 1e-12);
    /* damping = dt x 3e9 = 84553182.68 N s/m */
    REL(m.damping, 84553182.67728049, 1e-12);
    /* v = 25 dt = 0.704610 m/s; displacement per step = 25 dt^2 = 0.0198590 m */
    REL(m.boundary_speed, 25.0 * 0.028184394225760162, 1e-12);
    REL(m.displacement_per_step, 25.0 * 0.028184394225760162 * 0.028184394225760162, 1e-12);
    assert_true(m.gravity == 9.81);
    assert_true(m.width_m == 10000.0 && m.height_m == 5000.0);
}

static void test_model_default_increment_schedule(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_model m = derive(&p);
    /* 400 s / 0.0281844 s = 14192.2 -> 14192 steps; 2000 s -> 70961 steps */
    assert_int_equal(m.equil_steps, 14192);
    assert_int_equal(m.total_steps, 70961);
    /* 5 m / 0.0198590 m = 251.78 steps per increment; 14192 / 251.78 = 56.4 -> 56;
     * (70961 - 14192) / 251.78 = 225.5 -> 226 more: 282 */
    REL(m.display_steps, 251.775, 1e-5);
    assert_int_equal(m.n_increments_equil, 56);
    assert_int_equal(m.n_increments_total, 282);
    /* 56769 steps x 0.0198590 m = 1127.4 m, "about 1130 m" */
    assert_true(m.total_displacement > 1120.0 && m.total_displacement < 1135.0);
    REL(m.total_displacement, 56769.0 * m.displacement_per_step, 1e-12);
}

static void test_model_scaled_constants_200m(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    p.unit_scaling = 200.0;
    cdem_model m = derive(&p);
    /* radii 10, 15, 20, 25 m; average 17.5 m; min mass 2500 pi 10^2 = 785398.163 kg */
    assert_true(m.average_radius == 17.5);
    REL(m.min_mass, 785398.1633974483, 1e-12);
    /* Kn = Ks = 17.5 x 19944125.80 = 349022201.5 N/m */
    REL(m.kn, 349022201.5, 1e-12);
    assert_true(m.ks == m.kn);
    /* damping = 17.5 x 1091596.58430158 = 19102940.2253 N s/m */
    REL(m.damping, 19102940.22527765, 1e-12);
    /* dt = 0.25 sqrt(785398.163 / 349022201.5) = 0.25 x 0.0474371 = 0.0118593 s */
    REL(m.dt, 0.011859282720129805, 1e-12);
}

static void test_model_keep_constants_200m(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    p.unit_scaling = 200.0;
    p.keep_constants = 1;
    cdem_model m = derive(&p);
    assert_true(m.kn == 1544871985.0);
    /* dt = 0.25 sqrt(785398.163 / 1544871985) = 0.00563688 s, one fifth of the 1000 m dt
     * (the elements are five times smaller), as the paper says */
    REL(m.dt, 0.005636878845152032, 1e-12);
    REL(m.dt * 5.0, 0.028184394225760162, 1e-12);
    /* damping = dt x 3e9 = 16910636.54 N s/m */
    REL(m.damping, 16910636.535456095, 1e-12);
}

static void test_model_half_radii_halve_dt(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_model full = derive(&p);
    p.half_radii = 1;
    cdem_model half = derive(&p);
    assert_true(half.radius[0] == 25.0 && half.radius[3] == 62.5);
    /* mass / 4 -> dt / 2 = 0.0140922 s; speed halves too */
    REL(half.dt, 0.014092197112880081, 1e-12);
    REL(half.dt, full.dt / 2.0, 1e-12);
    REL(half.boundary_speed, full.boundary_speed / 2.0, 1e-12);
}

/* The boundary-speed relation reproduces the paper's biaxial tests: axial strain 0.2 of the
 * sample height in each of its four set-ups. */
static void test_model_speed_reproduces_paper_biaxial_strain(void **state) {
    (void)state;
    static const struct {
        double unit_scaling, equil, runtime;
        int half, keep;
        double expected_strain, tol;
    } cases[] = {
        {1000, 800, 2220, 0, 0, 0.2, 0.01},  /* Fig. 4A */
        {1000, 1600, 4440, 1, 0, 0.2, 0.01}, /* Fig. 4B, half radii: twice the times */
        {200, 800, 2220, 0, 1, 0.2, 0.01},   /* Fig. 5A, default constants */
        {200, 400, 1050, 0, 0, 0.2, 0.05},   /* Fig. 5B, scaled constants (0.193) */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cdem_params p;
        cdem_params_defaults(&p);
        p.mode = CDEM_MODE_BIAXIAL;
        p.unit_scaling = cases[i].unit_scaling;
        p.equilibration = cases[i].equil;
        p.runtime = cases[i].runtime;
        p.half_radii = cases[i].half;
        p.keep_constants = cases[i].keep;
        cdem_model m = derive(&p);
        assert_true(m.gravity == 0.0); /* gravity off in the biaxial test */
        double strain = m.total_displacement / m.height_m;
        if (fabs(strain - cases[i].expected_strain) > cases[i].tol)
            print_error("case %zu: axial strain %g\n", i, strain);
        assert_true(fabs(strain - cases[i].expected_strain) <= cases[i].tol);
    }
}

static void test_model_increment_step_endpoints(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_model m = derive(&p);
    assert_int_equal(cdem_model_increment_step(&m, 0), 0);
    assert_int_equal(cdem_model_increment_step(&m, -3), 0);
    assert_int_equal(cdem_model_increment_step(&m, 56), 14192);
    assert_int_equal(cdem_model_increment_step(&m, 282), 70961);
    assert_int_equal(cdem_model_increment_step(&m, 1000), 70961);
    /* equilibration increments evenly spaced: 14192 / 56 = 253.43 -> 253 */
    assert_int_equal(cdem_model_increment_step(&m, 1), 253);
    /* first deformation increment one display interval (251.78 steps) after equilibration */
    assert_int_equal(cdem_model_increment_step(&m, 57), 14192 + 252);
    /* second to last: 14192 + round(225 x 251.775) = 14192 + 56649 */
    assert_int_equal(cdem_model_increment_step(&m, 281), 14192 + lround(225.0 * m.display_steps));
    long prev = -1;
    for (int k = 0; k <= m.n_increments_total; k++) {
        long s = cdem_model_increment_step(&m, k);
        assert_true(s > prev);
        prev = s;
    }
    assert_int_equal(cdem_model_increment_step(NULL, 5), 0);
}

static void test_model_repose_display_interval_in_seconds(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_REPOSE; /* display interval in seconds: 10 s per increment */
    p.display_interval = 10.0;
    cdem_model m = derive(&p);
    assert_true(m.total_displacement == 0.0); /* repose: no boundary moves */
    REL(m.display_steps, 10.0 / m.dt, 1e-12);
    /* 10 s / 0.0281844 s = 354.807 steps; 14192 / 354.807 = 39.9998 -> 40;
     * (70961 - 14192) / 354.807 = 159.9998 -> ceil 160: 200 in all */
    assert_int_equal(m.n_increments_equil, 40);
    assert_int_equal(m.n_increments_total, 200);
    assert_int_equal(cdem_model_increment_step(&m, 200), m.total_steps);
}

static void test_model_light_interval_min_mass(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    p.weak_density_percent = 50.0;
    cdem_model off = derive(&p); /* interval off: density percent ignored */
    REL(off.min_mass, 19634954.08493621, 1e-12);
    p.weak_interval = CDEM_WEAK_LOWER;
    cdem_model on = derive(&p);
    REL(on.min_mass, 19634954.08493621 * 0.5, 1e-12);
    /* dt = 0.25 sqrt(m/2 / Kn) = dt_default / sqrt 2 */
    REL(on.dt, off.dt / sqrt(2.0), 1e-12);
}

static void test_model_sediment_settling_sea_level(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    p.sea_level_rise = CDEM_SEA_HIGH;
    cdem_model m = derive(&p);
    /* 30 x 5 m = 150 m; 150 / 0.0198590 = 7553.2 -> 7553 steps */
    assert_true(m.sediment_interval == 150.0);
    assert_int_equal(m.sediment_steps, lround(150.0 / m.displacement_per_step));
    assert_int_equal(m.sediment_steps, 7553);
    /* 0.2 x 400 s = 80 s / 0.0281844 = 2838.4 -> 2838 steps */
    assert_int_equal(m.settling_steps, 2838);
    assert_true(m.sea_level_factor == 0.75);
    static const double factors[] = {0.0, 0.25, 0.5, 0.75, 1.0};
    for (int s = 0; s < 5; s++) {
        p.sea_level_rise = (cdem_sea_level_rise)s;
        m = derive(&p);
        assert_true(m.sea_level_factor == factors[s]);
    }
}

static void test_model_estimate_elements(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    assert_int_equal(cdem_model_estimate_elements(&p), 2121);
    p.half_radii = 1;
    assert_int_equal(cdem_model_estimate_elements(&p), 8484); /* paper: 8342 */
    p.width = 15;
    p.height = 3;
    /* 2121 x 45/50 x 4 = 7635.6 -> 7636 (paper: 7600) */
    assert_int_equal(cdem_model_estimate_elements(&p), 7636);
    p.width = 25;
    p.height = 2.5;
    /* 2121 x 62.5/50 x 4 = 10605 (paper: 10520) */
    assert_int_equal(cdem_model_estimate_elements(&p), 10605);
    assert_int_equal(cdem_model_estimate_elements(NULL), 0);
}

static void test_model_derive_rejects_unusable(void **state) {
    (void)state;
    cdem_params p;
    cdem_model m;
    cdem_error err;
    cdem_params_defaults(&p);
    p.unit_scaling = 0.0;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "unit_scaling = 0 m"));
    cdem_params_defaults(&p);
    p.display_interval = -1.0;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "display_interval = -1"));
    p.display_interval = NAN;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_ERR_RANGE);
    assert_int_equal(cdem_bc_derive_model(NULL, &m, &err), CDEM_ERR_INVALID);
    assert_int_equal(cdem_model_derive(NULL, NULL, &m, &err), CDEM_ERR_INVALID);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_model_default_constants_1000m),
        cmocka_unit_test(test_model_default_increment_schedule),
        cmocka_unit_test(test_model_scaled_constants_200m),
        cmocka_unit_test(test_model_keep_constants_200m),
        cmocka_unit_test(test_model_half_radii_halve_dt),
        cmocka_unit_test(test_model_speed_reproduces_paper_biaxial_strain),
        cmocka_unit_test(test_model_increment_step_endpoints),
        cmocka_unit_test(test_model_repose_display_interval_in_seconds),
        cmocka_unit_test(test_model_light_interval_min_mass),
        cmocka_unit_test(test_model_sediment_settling_sea_level),
        cmocka_unit_test(test_model_estimate_elements),
        cmocka_unit_test(test_model_derive_rejects_unusable),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
