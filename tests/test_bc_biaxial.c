/* Tests of the biaxial mode (solver/modes/bc_biaxial.c) and the confining pressure of the
 * integrator: the ramp, the edge force on a hand-made pair (analytic), the edge search on a
 * real sample (sum of the lateral forces = p x height within one band), parameter errors, and
 * a short end-to-end 10 x 5 run (equilibration 100 s, runtime 150 s) read back: platen
 * travel, lateral walls gone, edges flagged, axial strain = closure / initial height in the
 * increments and the series, differential stress zero right after equilibration. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "assert_near.h"
#include "bc.h"
#include "contact.h"
#include "h5format.h"
#include "integrate.h"
#include "model.h"
#include "run.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PRESSURE 1e7 /* N/m */

static cdem_params biaxial_params(void) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_BIAXIAL;
    p.width = 10.0;
    p.height = 5.0;
    p.confining_pressure = PRESSURE;
    p.equilibration = 100.0;
    p.runtime = 150.0;
    p.series_interval = 50;
    return p;
}

static void test_bc_biaxial_ramp(void **st) {
    (void)st;
    assert_near(cdem_bc_confining_ramp(0, 100), 0.0, 0.0);
    assert_near(cdem_bc_confining_ramp(50, 100), 0.0, 0.0);
    assert_near(cdem_bc_confining_ramp(75, 100), 0.5, 1e-15);
    assert_near(cdem_bc_confining_ramp(100, 100), 1.0, 0.0);
    assert_near(cdem_bc_confining_ramp(5000, 100), 1.0, 0.0);
    assert_near(cdem_bc_confining_ramp(3, 0), 1.0, 0.0);
}

/* Two free elements in one band, far apart, and one between them (not an edge), no gravity:
 * the left one is pushed in +x and the right one in -x by p x band height x ramp; a fourth
 * element alone in a higher band is flagged once. */
static void test_bc_biaxial_edge_force_analytic(void **st) {
    (void)st;
    cdem_params p = biaxial_params();
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_integrator it;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    cdem_state s;
    assert_int_equal(cdem_state_init(&s, 8, 0, &err), CDEM_OK);
    const double r = m.radius[0];
    assert_int_equal(cdem_state_append(&s, -1, 0.0, 0.0, r, 1.0, 1, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 100 * r, 0.0, r, 1.0, 1, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 10 * r, 0.0, r, 1.0, 1, 0, 0, NULL, &err), CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, 30 * r, 40 * m.max_radius, r, 1.0, 1, 0, 0, NULL, &err), CDEM_OK);
    /* ramp at step 0 of 100 steps of equilibration: no force yet, but the edges are found */
    assert_int_equal(cdem_loads_set_confining(&it.loads, PRESSURE, 100, it.step, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    /* the list may re-sort the state: find the elements by position */
    size_t il = SIZE_MAX, ir = SIZE_MAX, ic = SIZE_MAX, iu = SIZE_MAX;
    for (size_t i = 0; i < s.n; i++) {
        if (s.y[i] > 0.0)
            iu = i;
        else if (s.x[i] < 5 * r)
            il = i;
        else if (s.x[i] > 50 * r)
            ir = i;
        else
            ic = i;
    }
    assert_true(il < s.n && ir < s.n && ic < s.n && iu < s.n);
    assert_int_equal(it.loads.n_edge, 3);
    assert_true(s.flags[il] & CDEM_FLAG_BIAXIAL_EDGE);
    assert_true(s.flags[ir] & CDEM_FLAG_BIAXIAL_EDGE);
    assert_true(s.flags[iu] & CDEM_FLAG_BIAXIAL_EDGE);
    assert_false(s.flags[ic] & CDEM_FLAG_BIAXIAL_EDGE);
    assert_near(s.fx[il], 0.0, 0.0);
    /* full pressure (equilibration over) */
    assert_int_equal(cdem_loads_set_confining(&it.loads, PRESSURE, 0, it.step, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    const double f = PRESSURE * it.loads.column_width;
    assert_near(it.loads.column_width, 2.0 * it.removal.max_radius, 1e-12);
    assert_near(s.fx[il], f, 1e-9 * f);
    assert_near(s.fx[ir], -f, 1e-9 * f);
    assert_near(s.fx[ic], 0.0, 0.0);
    /* alone in its band and left of the middle of the free span: pushed in +x once */
    assert_near(s.fx[iu], f, 1e-9 * f);
    assert_near(s.fy[il], 0.0, 0.0); /* gravity off in the biaxial test */
    /* a negative or NaN pressure is refused with the key */
    assert_int_equal(cdem_loads_set_confining(&it.loads, -1.0, 0, it.step, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "boundary.confining_pressure = -1"));
    assert_int_equal(cdem_loads_set_confining(&it.loads, NAN, 0, it.step, &err), CDEM_ERR_RANGE);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

/* One free disc (radius 125 m, no gravity) on a short bottom platen; the mode adds the top
 * platen. Equilibration steps (cdem_bc_apply with k = 0 runs the servo) for twice the ramp:
 * both platens must end up carrying the confining pressure over the sample width, F = p x 2r
 * (the disc is the whole sample), and the platens must have moved (the servo closed the gap
 * until the disc is squeezed by F / Kn in total). */
static void test_bc_biaxial_servo_platens_carry_the_pressure(void **st) {
    (void)st;
    cdem_params p = biaxial_params();
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    m.equil_steps = 200;
    m.total_steps = 600;
    cdem_state s;
    assert_int_equal(cdem_state_init(&s, 64, 0, &err), CDEM_OK);
    const double rw = m.radius[0], R = m.radius[3];
    for (int k = -6; k <= 6; k++)
        assert_int_equal(
            cdem_state_append(&s, -1, k * rw, 0.0, rw, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
    const double mass = p.density * M_PI * R * R;
    assert_int_equal(cdem_state_append(&s, -1, 0.0, rw + R, R, mass, 1, 0, 0, NULL, &err), CDEM_OK);
    cdem_bc bc;
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_OK);
    assert_true(cdem_bc_moves_in_equilibration(&bc));
    cdem_integrator it;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_loads_set_confining(&it.loads, PRESSURE, m.equil_steps, it.step, &err),
                     CDEM_OK);
    double top0 = -INFINITY;
    for (size_t i = 0; i < s.n; i++)
        if ((s.flags[i] & CDEM_FLAG_MOVING) && s.y[i] > rw)
            top0 = fmax(top0, s.y[i]);
    for (long j = 1; j <= 2 * m.equil_steps; j++)
        assert_int_equal(cdem_integrator_step(&it, &s, &bc, 0, m.displacement_per_step, &err),
                         CDEM_OK);
    double ft = 0.0, fb = 0.0, top1 = -INFINITY, bot1 = INFINITY, yd = 0.0;
    for (size_t i = 0; i < s.n; i++) {
        if (!(s.flags[i] & CDEM_FLAGS_BOUNDARY)) {
            yd = s.y[i];
            continue;
        }
        if (s.y[i] > rw) {
            ft += s.fy[i];
            top1 = fmax(top1, s.y[i]);
        } else {
            fb += s.fy[i];
            bot1 = fmin(bot1, s.y[i]);
        }
    }
    const double target = PRESSURE * 2.0 * R;
    assert_near(ft, target, 0.02 * target);         /* the disc pushes the top platen up */
    assert_near(-fb, target, 0.02 * target);        /* and the bottom one down */
    assert_true(top1 < top0 - 0.5 * target / m.kn); /* the top platen came down */
    assert_true(bot1 > 0.0);                        /* the bottom one up */
    assert_true(yd > bot1 && yd < top1);
    /* the confining pressure is the lateral load of the mode */
    assert_near(cdem_bc_lateral_pressure(&bc), PRESSURE, 0.0);
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
}

/* Uniaxial (p = 0) through cdem_run: the sample keeps its contact network through the
 * equilibration and the platens carry no load before deformation. */
static void test_bc_biaxial_uniaxial_sample_stays_packed(void **st) {
    (void)st;
    char path[1024];
    scratch_path(path, sizeof path, "test_bc_biaxial_uniaxial.h5");
    cdem_params p = biaxial_params();
    p.confining_pressure = 0.0;
    p.runtime = 110.0;
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    if (cdem_run(&p, &o, &err) != CDEM_OK)
        fail_msg("cdem_run: %s", err.msg);
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    cdem_series_sample *q = NULL;
    size_t nq = 0;
    assert_int_equal(cdem_h5_reader_read_series(r, &q, &nq, &err), CDEM_OK);
    size_t last_eq = 0;
    for (size_t k = 0; k < nq; k++)
        if (q[k].step <= m.equil_steps)
            last_eq = k;
    assert_true(last_eq > 10 && last_eq + 1 < nq);
    assert_true(q[0].contacts > 1000);
    assert_true((double)q[last_eq].contacts >= 0.9 * (double)q[0].contacts);
    assert_near(q[last_eq].differential_stress, 0.0, 1e-9); /* no load on the platens */
    assert_true(q[nq - 1].contacts >= q[last_eq].contacts / 2);
    free(q);
    cdem_h5_reader_close(r);
}

static void test_bc_biaxial_refuses_bad_parameters(void **st) {
    (void)st;
    char path[1024];
    scratch_path(path, sizeof path, "test_bc_biaxial_refused.h5");
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    cdem_error err;
    cdem_params p = biaxial_params();
    p.confining_pressure = -5.0;
    assert_int_equal(cdem_run(&p, &o, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "confining_pressure = -5"));
    p = biaxial_params();
    p.overburden_pressure = 1e6;
    assert_int_equal(cdem_run(&p, &o, &err), CDEM_ERR_UNSUPPORTED);
    assert_non_null(strstr(err.msg, "overburden_pressure = 1e+06"));
}

/* Platen heights of s: mean y of the moving walls above / below y_mid. */
static void platens(const cdem_state *s, double y_mid, double *top, double *bottom, long *n_top,
                    long *n_bottom) {
    double t = 0.0, b = 0.0;
    long nt = 0, nb = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (!((s->flags[i] & CDEM_FLAG_WALL) && (s->flags[i] & CDEM_FLAG_MOVING)))
            continue;
        if (s->y[i] > y_mid) {
            t += s->y[i];
            nt++;
        } else {
            b += s->y[i];
            nb++;
        }
    }
    *top = nt ? t / (double)nt : NAN;
    *bottom = nb ? b / (double)nb : NAN;
    *n_top = nt;
    *n_bottom = nb;
}

static void test_bc_biaxial_end_to_end(void **st) {
    (void)st;
    char path[1024];
    scratch_path(path, sizeof path, "test_bc_biaxial_run.h5");
    cdem_params p = biaxial_params();
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    assert_true(m.gravity == 0.0);
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    if (cdem_run(&p, &o, &err) != CDEM_OK)
        fail_msg("cdem_run: %s", err.msg);

    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_non_null(strstr(cdem_h5_reader_summary(r), "biaxial test"));
    assert_non_null(strstr(cdem_h5_reader_summary(r), "platen contacts use material.wall_*"));
    assert_non_null(strstr(cdem_h5_reader_summary(r), "servo-controlled"));
    size_t ie = 0, il = 0;
    assert_int_equal(cdem_h5_reader_find_increment(r, "equil", &ie, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_find_increment(r, "last", &il, &err), CDEM_OK);
    cdem_state s0 = {0}, s1 = {0};
    cdem_increment_info i0, i1;
    assert_int_equal(cdem_h5_reader_load_increment(r, ie, &s0, &i0, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_load_increment(r, il, &s1, &i1, &err), CDEM_OK);
    assert_int_equal(i0.step, m.equil_steps);
    assert_int_equal(i1.step, m.total_steps);

    /* platens: top above, base below, both the same radius; they close by du per step */
    double ymin = INFINITY, ymax = -INFINITY;
    for (size_t i = 0; i < s0.n; i++)
        if (!(s0.flags[i] & CDEM_FLAGS_BOUNDARY)) {
            ymin = fmin(ymin, s0.y[i]);
            ymax = fmax(ymax, s0.y[i]);
        }
    const double y_mid = 0.5 * (ymin + ymax);
    double t0, b0, t1, b1;
    long nt0, nb0, nt1, nb1;
    platens(&s0, y_mid, &t0, &b0, &nt0, &nb0);
    platens(&s1, y_mid, &t1, &b1, &nt1, &nb1);
    assert_true(nt0 > 10 && nb0 > 10);
    assert_int_equal(nt1, nt0);
    assert_int_equal(nb1, nb0);
    const double closure = i1.net_displacement;
    const double expect_closure = (double)(m.total_steps - m.equil_steps) * m.displacement_per_step;
    assert_true(closure > 0.0);
    assert_near(closure, expect_closure, 1e-5 * expect_closure);
    assert_near(t0 - t1, 0.5 * closure, 1e-6 * closure);
    assert_near(b1 - b0, 0.5 * closure, 1e-6 * closure);

    /* lateral walls: present during equilibration, removed at the start of deformation */
    long walls0 = 0, walls1 = 0;
    for (size_t i = 0; i < s0.n; i++)
        walls0 += (s0.flags[i] & CDEM_FLAG_WALL) && !(s0.flags[i] & CDEM_FLAG_MOVING);
    for (size_t i = 0; i < s1.n; i++)
        walls1 += (s1.flags[i] & CDEM_FLAG_WALL) && !(s1.flags[i] & CDEM_FLAG_MOVING);
    assert_true(walls0 > 0);
    assert_int_equal(walls1, 0);

    /* axial strain = closure / initial height (between the platens' inner faces) */
    double rp = INFINITY;
    for (size_t i = 0; i < s0.n; i++)
        if (s0.flags[i] & CDEM_FLAG_MOVING)
            rp = fmin(rp, s0.radius[i]);
    const double h0 = (t0 - rp) - (b0 + rp);
    assert_true(h0 > 0.9 * m.height_m && h0 < 1.1 * m.height_m);
    assert_near(i0.axial_strain, 0.0, 0.0);
    assert_near(i1.axial_strain, closure / h0, 1e-6 * closure / h0);

    /* edges: flagged on both sides, one per band and side; the lateral forces they carry sum
     * to p x sample height within one band */
    long left = 0, right = 0;
    double xl = INFINITY, xr = -INFINITY;
    for (size_t i = 0; i < s1.n; i++)
        if (!(s1.flags[i] & CDEM_FLAGS_BOUNDARY)) {
            xl = fmin(xl, s1.x[i]);
            xr = fmax(xr, s1.x[i]);
        }
    double ylo = INFINITY, yhi = -INFINITY;
    for (size_t i = 0; i < s1.n; i++) {
        if (!(s1.flags[i] & CDEM_FLAG_BIAXIAL_EDGE))
            continue;
        assert_false(s1.flags[i] & CDEM_FLAGS_BOUNDARY);
        if (s1.x[i] < 0.5 * (xl + xr))
            left++;
        else
            right++;
    }
    for (size_t i = 0; i < s1.n; i++)
        if (!(s1.flags[i] & CDEM_FLAGS_BOUNDARY)) {
            ylo = fmin(ylo, s1.y[i]);
            yhi = fmax(yhi, s1.y[i]);
        }
    cdem_integrator it;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    const double band = it.loads.column_width;
    const double height = yhi - ylo;
    assert_true(fabs((double)left * PRESSURE * band - PRESSURE * height) <= PRESSURE * band);
    assert_true(fabs((double)right * PRESSURE * band - PRESSURE * height) <= PRESSURE * band);
    /* the search on the final positions finds the stored edges again (deterministic run;
     * elements moved less than the skin since the last rebuild) */
    assert_int_equal(cdem_loads_find_edges(&it.loads, &s1, &err), CDEM_OK);
    assert_int_equal(it.loads.n_edge, left + right);
    cdem_integrator_free(&it);

    /* time series: strain = closure / h0 at every sample; differential stress 0 at the first
     * sample of deformation, compressive (> 0) at the end */
    cdem_series_sample *q = NULL;
    size_t nq = 0;
    assert_int_equal(cdem_h5_reader_read_series(r, &q, &nq, &err), CDEM_OK);
    assert_true(nq > 10);
    int first = 1;
    for (size_t k = 0; k < nq; k++) {
        const double expect = q[k].net_displacement / h0;
        assert_near(q[k].axial_strain, expect, 1e-9 + 1e-9 * expect);
        if (q[k].step >= m.equil_steps && first) {
            assert_near(q[k].differential_stress, 0.0, 0.0);
            /* the servo platens carry most of p by the end of this short equilibration
             * (-0.37 p left; fixed platens left -0.68 p even after 800 s) */
            assert_true(k > 0 && q[k - 1].differential_stress > -0.5 * PRESSURE);
            first = 0;
        }
    }
    assert_false(first);
    assert_true(q[nq - 1].differential_stress > 0.0);
    assert_true(q[nq - 1].axial_strain > 0.0);
    free(q);
    cdem_state_free(&s0);
    cdem_state_free(&s1);
    cdem_h5_reader_close(r);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_biaxial_ramp),
        cmocka_unit_test(test_bc_biaxial_edge_force_analytic),
        cmocka_unit_test(test_bc_biaxial_servo_platens_carry_the_pressure),
        cmocka_unit_test(test_bc_biaxial_refuses_bad_parameters),
        cmocka_unit_test(test_bc_biaxial_end_to_end),
        cmocka_unit_test(test_bc_biaxial_uniaxial_sample_stays_packed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
