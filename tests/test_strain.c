/* test_strain: the neighbour least-squares fit and the finite-strain measures.
 * Homogeneous deformations of a random packing must give the analytical measures at every
 * element that has a fit; the closed-form fit must equal GSL's multifit; too few neighbours
 * and wall elements give NaN; elements are matched by id; results do not depend on the
 * thread count; cumulative strain sums the pairs. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "analysis_fixtures.h"
#include "strain.h"

#include <gsl/gsl_multifit.h>
#include <math.h>
#include <omp.h>
#include <string.h>

static void assert_close(double got, double want, double rel, const char *what) {
    double tol = rel * fmax(1.0, fabs(want));
    if (!(fabs(got - want) <= tol)) {
        print_error("%s: got %.17g want %.17g\n", what, got, want);
        fail();
    }
}

/* Axes are lines: compare angles modulo 180 degrees. */
static void assert_angle_close(double got, double want, double tol, const char *what) {
    double d = fmod(got - want, 180.0);
    if (d > 90.0)
        d -= 180.0;
    if (d < -90.0)
        d += 180.0;
    if (!(fabs(d) <= tol) || !(got > -90.0 && got <= 90.0)) {
        print_error("%s: angle %.17g want %.17g (mod 180)\n", what, got, want);
        fail();
    }
}

static void test_strain_fit_matches_gsl(void **st) {
    (void)st;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 7);
    for (int trial = 0; trial < 50; trial++) {
        size_t m = 3 + gsl_rng_uniform_int(rng, 20);
        double X[32], Y[32], u[32], v[32];
        gsl_matrix *A = gsl_matrix_alloc(m, 3), *cov = gsl_matrix_alloc(3, 3);
        gsl_vector *bu = gsl_vector_alloc(m), *bv = gsl_vector_alloc(m), *cu = gsl_vector_alloc(3),
                   *cv = gsl_vector_alloc(3);
        for (size_t k = 0; k < m; k++) {
            X[k] = 250.0 * (gsl_rng_uniform(rng) - 0.5);
            Y[k] = 250.0 * (gsl_rng_uniform(rng) - 0.5);
            u[k] = 3.0 * gsl_rng_uniform(rng) - 1.0 + 0.01 * X[k];
            v[k] = 2.0 * gsl_rng_uniform(rng) - 1.0 - 0.02 * Y[k];
            gsl_matrix_set(A, k, 0, 1.0);
            gsl_matrix_set(A, k, 1, X[k]);
            gsl_matrix_set(A, k, 2, Y[k]);
            gsl_vector_set(bu, k, u[k]);
            gsl_vector_set(bv, k, v[k]);
        }
        gsl_multifit_linear_workspace *w = gsl_multifit_linear_alloc(m, 3);
        double chisq;
        gsl_multifit_linear(A, bu, cu, cov, &chisq, w);
        gsl_multifit_linear(A, bv, cv, cov, &chisq, w);
        double g[4], t[2];
        assert_int_equal(cdem_strain_fit(m, X, Y, u, v, g, t), 1);
        assert_close(t[0], gsl_vector_get(cu, 0), 1e-10, "tx");
        assert_close(g[0], gsl_vector_get(cu, 1), 1e-10, "dux/dX");
        assert_close(g[1], gsl_vector_get(cu, 2), 1e-10, "dux/dY");
        assert_close(t[1], gsl_vector_get(cv, 0), 1e-10, "ty");
        assert_close(g[2], gsl_vector_get(cv, 1), 1e-10, "duy/dX");
        assert_close(g[3], gsl_vector_get(cv, 2), 1e-10, "duy/dY");
        gsl_multifit_linear_free(w);
        gsl_matrix_free(A);
        gsl_matrix_free(cov);
        gsl_vector_free(bu);
        gsl_vector_free(bv);
        gsl_vector_free(cu);
        gsl_vector_free(cv);
    }
    gsl_rng_free(rng);
}

static void test_strain_fit_degenerate(void **st) {
    (void)st;
    double X[4] = {0, 1, 2, 3}, Y[4] = {0, 2, 4, 6}, u[4] = {0, 1, 2, 3}, v[4] = {0};
    double g[4], t[2];
    assert_int_equal(cdem_strain_fit(4, X, Y, u, v, g, t), 0); /* collinear */
    assert_true(isnan(g[0]) && isnan(g[3]) && isnan(t[0]));
    assert_int_equal(cdem_strain_fit(2, X, Y, u, v, g, t), 0); /* two points */
    assert_true(isnan(g[1]));
}

/* One homogeneous deformation and its analytical answer. */
typedef struct {
    const char *name;
    double F[4];
    double e1, e3_neg, max_shear, dilation, rotation, angle1; /* angle NaN = not checked */
} hom_case;

static void check_homogeneous(const hom_case *c) {
    cdem_state ref = {0}, cur = {0};
    make_packing(&ref, 300, 3600.0, 2500.0, 11);
    cdem_error err;
    assert_int_equal(cdem_state_copy(&cur, &ref, &err), CDEM_OK);
    deform_affine(&cur, c->F, 3000.0, 1200.0);
    cdem_strain_measures *m = malloc(cur.n * sizeof *m);
    assert_int_equal(cdem_strain_compute(&ref, &cur, NULL, 0.0, m, &err), CDEM_OK);
    size_t free_n = 0, fitted = 0;
    for (size_t i = 0; i < cur.n; i++) {
        if (cur.flags[i] & CDEM_FLAGS_BOUNDARY) {
            assert_true(isnan(m[i].e1));
            continue;
        }
        free_n++;
        if (isnan(m[i].e1))
            continue;
        fitted++;
        assert_close(m[i].e1, c->e1, 1e-10, c->name);
        assert_close(m[i].e3_neg, c->e3_neg, 1e-10, c->name);
        assert_close(m[i].max_shear, c->max_shear, 1e-10, c->name);
        assert_close(m[i].dilation, c->dilation, 1e-10, c->name);
        assert_close(m[i].rotation, c->rotation, 1e-10, c->name);
        if (!isnan(c->angle1))
            assert_angle_close(m[i].angle1, c->angle1, 1e-8, c->name);
    }
    /* every element of a packing this dense has enough neighbours */
    assert_true(free_n > 250);
    assert_int_equal(fitted, free_n);
    free(m);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

static void test_strain_homogeneous_exact(void **st) {
    (void)st;
    const double a = 1.2, b = 0.7, gam = 0.4, th = 0.3, ph = 0.5;
    /* simple shear: lambda = 1 + g^2/2 +- g sqrt(1 + g^2/4) */
    const double q = sqrt(1.0 + gam * gam / 4.0);
    const double S1s = gam / 2.0 + q, S3s = 1.0 / S1s;
    /* combination F = R(th) Q(ph) diag(a, b) Q(ph)^T: stretches a, b; S1 at th + ph */
    const double cq = cos(ph), sq = sin(ph), cr = cos(th), sr = sin(th);
    const double U[4] = {a * cq * cq + b * sq * sq, (a - b) * cq * sq, (a - b) * cq * sq,
                         a * sq * sq + b * cq * cq};
    const double Fc[4] = {cr * U[0] - sr * U[2], cr * U[1] - sr * U[3], sr * U[0] + cr * U[2],
                          sr * U[1] + cr * U[3]};
    const hom_case cases[] = {
        {"pure shear",
         {a, 0, 0, 1.0 / a},
         a - 1,
         1 - 1 / a,
         (a * a - 1 / (a * a)) / 2.0,
         0.0,
         0.0,
         0.0},
        {"pure shear vertical",
         {b, 0, 0, 1.0 / b},
         1 / b - 1,
         1 - b,
         (1 / (b * b) - b * b) / 2.0,
         0.0,
         0.0,
         90.0},
        {"simple shear",
         {1, gam, 0, 1},
         S1s - 1,
         1 - S3s,
         gam * q,
         0.0,
         gam / 2.0,
         0.5 * atan2(2 * gam, gam * gam) * 180 / M_PI},
        {"rigid rotation", {cos(th), -sin(th), sin(th), cos(th)}, 0, 0, 0, 0, -sin(th), NAN},
        {"dilation", {a, 0, 0, a}, a - 1, 1 - a, 0, a * a - 1, 0, NAN},
        {"combination",
         {Fc[0], Fc[1], Fc[2], Fc[3]},
         a - 1,
         1 - b,
         (a * a - b * b) / (2 * a * b),
         a * b - 1,
         0.5 * (Fc[1] - Fc[2]),
         (th + ph) * 180 / M_PI},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
        check_homogeneous(&cases[k]);
}

static void test_strain_few_neighbours_nan(void **st) {
    (void)st;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    cdem_state_init(&ref, 8, 0, &err);
    /* a lone pair (2 elements within reach) and a well-surrounded triple far away */
    cdem_state_append(&ref, -1, 0, 0, 100, 1, 1, 0, 0, NULL, &err);
    cdem_state_append(&ref, -1, 150, 0, 100, 1, 1, 0, 0, NULL, &err);
    cdem_state_append(&ref, -1, 5000, 0, 100, 1, 1, 0, 0, NULL, &err);
    cdem_state_append(&ref, -1, 5150, 0, 100, 1, 1, 0, 0, NULL, &err);
    cdem_state_append(&ref, -1, 5000, 150, 100, 1, 1, 0, 0, NULL, &err);
    cdem_state_copy(&cur, &ref, &err);
    for (size_t i = 0; i < cur.n; i++)
        cur.x[i] *= 1.1;
    cdem_strain_measures m[5];
    assert_int_equal(cdem_strain_compute(&ref, &cur, NULL, 0.0, m, &err), CDEM_OK);
    assert_true(isnan(m[0].e1) && isnan(m[0].max_shear) && isnan(m[0].dilation));
    assert_true(isnan(m[1].e1));
    /* the triple sees all three: exact 10 % extension in x */
    assert_close(m[2].e1, 0.1, 1e-12, "triple e1");
    assert_close(m[2].dilation, 0.1, 1e-12, "triple dilation");
    /* empty states: nothing to do, no crash */
    cdem_state empty;
    cdem_state_init(&empty, 1, 0, &err);
    assert_int_equal(cdem_strain_compute(&empty, &cur, NULL, 0.0, m, &err), CDEM_OK);
    assert_true(isnan(m[4].e1));
    cdem_state_free(&empty);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

static void test_strain_walls_excluded(void **st) {
    (void)st;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    make_packing(&ref, 200, 4000.0, 2000.0, 3);
    cdem_state_copy(&cur, &ref, &err);
    const double F[4] = {1.1, 0.05, 0.0, 0.95};
    deform_affine(&cur, F, 0, 0);
    /* throw the wall elements around: they must not enter any fit */
    for (size_t i = 0; i < cur.n; i++)
        if (cur.flags[i] & CDEM_FLAG_WALL) {
            cur.x[i] += 333.0 * (double)(i % 7);
            cur.y[i] -= 71.0;
        }
    cdem_strain_measures *m = malloc(cur.n * sizeof *m);
    assert_int_equal(cdem_strain_compute(&ref, &cur, NULL, 0.0, m, &err), CDEM_OK);
    cdem_strain_measures want;
    const double G[4] = {F[0] - 1, F[1], F[2], F[3] - 1};
    cdem_strain_measures_from_gradient(G, &want);
    for (size_t i = 0; i < cur.n; i++) {
        if (cur.flags[i] & CDEM_FLAG_WALL) {
            assert_true(isnan(m[i].e1) && isnan(m[i].rotation));
        } else {
            assert_close(m[i].max_shear, want.max_shear, 1e-10, "near wall");
        }
    }
    free(m);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

static void test_strain_matches_by_id(void **st) {
    (void)st;
    cdem_state ref = {0}, cur = {0}, cur2 = {0};
    cdem_error err;
    make_packing(&ref, 250, 5000.0, 2400.0, 5);
    cdem_state_copy(&cur, &ref, &err);
    /* a non-homogeneous field so that every element's value is distinct */
    for (size_t i = 0; i < cur.n; i++) {
        cur.x[i] += 30.0 * sin(cur.y[i] / 300.0);
        cur.y[i] += 20.0 * cos(cur.x[i] / 400.0);
    }
    cdem_strain_measures *m = malloc(cur.n * sizeof *m);
    assert_int_equal(cdem_strain_compute(&ref, &cur, NULL, 0.0, m, &err), CDEM_OK);
    /* cur2: reversed order, every 10th element removed, two new elements added */
    cdem_state_init(&cur2, cur.n, 0, &err);
    for (size_t k = cur.n; k-- > 0;)
        if (k % 10 != 3)
            cdem_state_append(&cur2, cur.id[k], cur.x[k], cur.y[k], cur.radius[k], 1, cur.layer[k],
                              cur.flags[k], 0, NULL, &err);
    cdem_state_append(&cur2, 100000, 1000, 600, 50, 1, 25, CDEM_FLAG_GROWTH, 3, NULL, &err);
    cdem_state_append(&cur2, 100001, 1200, 600, 50, 1, 25, CDEM_FLAG_GROWTH, 3, NULL, &err);
    cdem_strain_measures *m2 = malloc(cur2.n * sizeof *m2);
    assert_int_equal(cdem_strain_compute(&ref, &cur2, NULL, 0.0, m2, &err), CDEM_OK);
    /* removed elements are missing from both configurations' fits, so compare with a
     * reference computed on ref restricted to the kept ids */
    cdem_state ref2;
    cdem_state_init(&ref2, ref.n, 0, &err);
    for (size_t k = 0; k < ref.n; k++)
        if (k % 10 != 3)
            cdem_state_append(&ref2, ref.id[k], ref.x[k], ref.y[k], ref.radius[k], 1, ref.layer[k],
                              ref.flags[k], 0, NULL, &err);
    cdem_strain_measures *m3 = malloc(cur.n * sizeof *m3);
    assert_int_equal(cdem_strain_compute(&ref2, &cur, NULL, 0.0, m3, &err), CDEM_OK);
    size_t checked = 0;
    for (size_t i = 0; i < cur2.n; i++) {
        if (cur2.id[i] >= 100000) {
            assert_true(isnan(m2[i].e1)); /* absent from the reference */
            continue;
        }
        size_t k = (size_t)cur2.id[i];
        assert_int_equal(cur.id[k], cur2.id[i]);
        if (isnan(m3[k].e1)) {
            assert_true(isnan(m2[i].e1));
            continue;
        }
        assert_close(m2[i].e1, m3[k].e1, 1e-12, "by id e1");
        assert_close(m2[i].rotation, m3[k].rotation, 1e-12, "by id rotation");
        checked++;
    }
    assert_true(checked > 150);
    /* and the removal really changes some values (the test can fail) */
    int differs = 0;
    for (size_t k = 0; k < cur.n; k++)
        if (isfinite(m[k].e1) && isfinite(m3[k].e1) && fabs(m[k].e1 - m3[k].e1) > 1e-9)
            differs = 1;
    assert_true(differs);
    free(m);
    free(m2);
    free(m3);
    cdem_state_free(&ref);
    cdem_state_free(&ref2);
    cdem_state_free(&cur);
    cdem_state_free(&cur2);
}

static void test_strain_thread_count_invariant(void **st) {
    (void)st;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    make_packing(&ref, 400, 7000.0, 3000.0, 9);
    cdem_state_copy(&cur, &ref, &err);
    for (size_t i = 0; i < cur.n; i++) {
        cur.x[i] += 25.0 * sin(cur.y[i] / 200.0) + 0.01 * cur.x[i];
        cur.y[i] += 15.0 * cos(cur.x[i] / 350.0);
    }
    cdem_strain_measures *a = malloc(cur.n * sizeof *a), *b = malloc(cur.n * sizeof *b);
    omp_set_num_threads(1);
    assert_int_equal(cdem_strain_compute(&ref, &cur, NULL, 0.0, a, &err), CDEM_OK);
    omp_set_num_threads(2);
    assert_int_equal(cdem_strain_compute(&ref, &cur, NULL, 0.0, b, &err), CDEM_OK);
    omp_set_num_threads(3);
    assert_int_equal(cdem_strain_compute(&ref, &cur, NULL, 0.0, a, &err), CDEM_OK);
    assert_memory_equal(a, b, cur.n * sizeof *a);
    free(a);
    free(b);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

static void test_strain_cumulative_sums_pairs(void **st) {
    (void)st;
    cdem_state s0 = {0}, s1 = {0}, s2 = {0};
    cdem_error err;
    make_packing(&s0, 200, 4000.0, 2000.0, 21);
    cdem_state_copy(&s1, &s0, &err);
    const double F1[4] = {1, 0.05, 0, 1};
    deform_affine(&s1, F1, 0, 0);
    cdem_state_copy(&s2, &s1, &err);
    const double F2[4] = {1.02, 0, 0, 1 / 1.02};
    deform_affine(&s2, F2, 0, 0);
    cdem_strain_measures *p1 = malloc(s0.n * sizeof *p1), *p2 = malloc(s0.n * sizeof *p2),
                         *c = malloc(s0.n * sizeof *c);
    cdem_strain_compute(&s0, &s1, NULL, 0, p1, &err);
    cdem_strain_compute(&s1, &s2, NULL, 0, p2, &err);
    cdem_strain_cum cum;
    cdem_strain_cum_init(&cum);
    cdem_strain_cum_get(&cum, &s0, 1, c);
    for (size_t i = 0; i < s0.n; i++)
        if (!(s0.flags[i] & CDEM_FLAG_WALL))
            assert_true(c[i].max_shear == 0.0);
    assert_int_equal(cdem_strain_cum_add(&cum, &s1, p1, &err), CDEM_OK);
    assert_int_equal(cdem_strain_cum_add(&cum, &s2, p2, &err), CDEM_OK);
    cdem_strain_cum_get(&cum, &s2, 0, c);
    const double want = 0.05 * sqrt(1 + 0.05 * 0.05 / 4) + (1.02 * 1.02 - 1 / (1.02 * 1.02)) / 2;
    for (size_t i = 0; i < s2.n; i++) {
        if (s2.flags[i] & CDEM_FLAG_WALL) {
            assert_true(isnan(c[i].max_shear));
            continue;
        }
        assert_close(c[i].max_shear, want, 1e-10, "cumulative shear");
        assert_close(c[i].rotation, 0.025, 1e-10, "cumulative rotation");
        assert_true(isnan(c[i].angle1));
    }
    s2.id[0] = -4;
    assert_int_equal(cdem_strain_cum_add(&cum, &s2, p2, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "negative id -4"));
    cdem_strain_cum_free(&cum);
    cdem_strain_cum_free(NULL);
    free(p1);
    free(p2);
    free(c);
    cdem_state_free(&s0);
    cdem_state_free(&s1);
    cdem_state_free(&s2);
}

static void test_strain_stress_principal(void **st) {
    (void)st;
    cdem_stress_principal p;
    cdem_stress_principal_from(30e6, 10e6, 10e6, &p);
    assert_close(p.sigma1, 20e6 + sqrt(2) * 10e6, 1e-14, "sigma1");
    assert_close(p.sigma3, 20e6 - sqrt(2) * 10e6, 1e-14, "sigma3");
    assert_close(p.max_shear, sqrt(2) * 10e6, 1e-14, "max shear");
    assert_close(p.angle1, 22.5, 1e-12, "angle");
    cdem_stress_principal_from(5e6, 5e6, 0, &p);
    assert_true(isnan(p.angle1));
    assert_close(p.sigma1, 5e6, 0, "isotropic");
}

static void test_strain_bad_input_no_crash(void **st) {
    (void)st;
    cdem_state ref = {0}, cur = {0};
    cdem_error err;
    make_packing(&ref, 150, 3000.0, 1500.0, 2);
    /* one element absurdly far away, one with a NaN position in cur, one with radius NaN */
    ref.x[0] = 1e300;
    ref.radius[2] = NAN;
    cdem_state_copy(&cur, &ref, &err);
    const double F[4] = {1.05, 0, 0, 1};
    deform_affine(&cur, F, 0, 0);
    cur.x[0] = 1e300;
    cur.y[1] = NAN;
    cdem_strain_measures *m = malloc(cur.n * sizeof *m);
    assert_int_equal(cdem_strain_compute(&ref, &cur, NULL, 0.0, m, &err), CDEM_OK);
    assert_true(isnan(m[0].e1)); /* alone */
    assert_true(isnan(m[1].e1)); /* no displacement */
    size_t ok = 0;
    for (size_t i = 3; i < cur.n; i++)
        if (!(cur.flags[i] & CDEM_FLAG_WALL) && isfinite(m[i].e1)) {
            assert_close(m[i].e1, 0.05, 1e-10, "far-away element ignored");
            ok++;
        }
    assert_true(ok > 100);
    free(m);
    cdem_state_free(&ref);
    cdem_state_free(&cur);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_strain_fit_matches_gsl),
        cmocka_unit_test(test_strain_fit_degenerate),
        cmocka_unit_test(test_strain_homogeneous_exact),
        cmocka_unit_test(test_strain_few_neighbours_nan),
        cmocka_unit_test(test_strain_walls_excluded),
        cmocka_unit_test(test_strain_matches_by_id),
        cmocka_unit_test(test_strain_thread_count_invariant),
        cmocka_unit_test(test_strain_cumulative_sums_pairs),
        cmocka_unit_test(test_strain_stress_principal),
        cmocka_unit_test(test_strain_bad_input_no_crash),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
