/* Tests of faults.[ch] (fault zones picked from a strain field) on a random packing with
 * strain bands of known position, dip and dip direction. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "analysis_fixtures.h"
#include "faults.h"
#include "surface.h"

#define W 12000.0
#define H 4000.0

/* Distance of (x, y) to the line through (x0, H) dipping `dip` degrees toward +x (right = 1)
 * or -x. */
static double band_distance(double x, double y, double x0, double dip, int right) {
    const double t = dip * M_PI / 180.0;
    /* direction down the dip: (cos t, -sin t) to the right, (-cos t, -sin t) to the left */
    const double dx = right ? cos(t) : -cos(t), dy = -sin(t);
    const double px = x - x0, py = y - H;
    return fabs(px * dy - py * dx);
}

/* Values: 2 inside each band (half-width 250 m: about four elements across), 0.1 elsewhere, NaN on
 * boundary elements. */
static double *band_values(const cdem_state *s, int nb, const double *x0, const double *dip,
                           const int *right) {
    double *v = malloc(s->n * sizeof *v);
    assert_non_null(v);
    for (size_t i = 0; i < s->n; i++) {
        v[i] = (s->flags[i] & CDEM_FLAGS_BOUNDARY) ? NAN : 0.1;
        for (int b = 0; b < nb && !(s->flags[i] & CDEM_FLAGS_BOUNDARY); b++)
            if (band_distance(s->x[i], s->y[i], x0[b], dip[b], right[b]) < 250.0)
                v[i] = 2.0;
    }
    return v;
}

/* The packing and the values of a graben: a 60-degree fault dipping right from x = 3 km and a
 * 45-degree one dipping left from x = 10 km; they do not meet above the base. */
static const double graben_x0[2] = {3000.0, 10000.0}, graben_dip[2] = {60.0, 45.0};
static const int graben_right[2] = {1, 0};
static double *graben(cdem_state *s) {
    make_packing(s, 6000, W, H, 3);
    return band_values(s, 2, graben_x0, graben_dip, graben_right);
}

static void test_faults_two_bands(void **unused) {
    (void)unused;
    cdem_state s;
    double *v = graben(&s);
    const double *x0 = graben_x0, *dip = graben_dip;
    const int *right = graben_right;
    cdem_faults_options o;
    cdem_faults_default_options(&o);
    cdem_faults_result r;
    cdem_error err;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_OK);
    assert_int_equal(r.n, 2);
    assert_true(r.bin == 250.0); /* 2 x the largest radius of the fixture, 125 m */
    for (int b = 0; b < 2; b++) {
        const cdem_fault_zone *z = &r.zone[b];
        printf("    zone %d: top (%.0f, %.0f) bottom (%.0f, %.0f) dip %.1f %s rows %d\n", b,
               z->x_top, z->y_top, z->x_bottom, z->y_bottom, z->dip_deg,
               z->dips_right ? "right" : "left", z->rows);
        assert_int_equal(z->dips_right, right[b]);
        assert_true(fabs(z->dip_deg - dip[b]) < 4.0);
        assert_true(fabs(z->x_top - x0[b]) < 400.0);
        assert_true(z->rows >= 12);
        /* the default threshold takes in the 1-2-1 smoothed edges of the bands too */
        assert_true(z->mean_value > 0.5 && z->max_value <= 2.0 + 1e-12);
    }
    cdem_faults_free(&r);
    free(v);
    cdem_state_free(&s);
}

/* Salt (issue 37): the lowest fifth of the packing made salt with a high, spread strain (a
 * viscous layer's flow). Left out by default, the picks are those of the cover alone: the
 * same zones and threshold as with no salt at all; with include_salt the salt's strain
 * fills its rows, one pick each, which make a zone of their own. */
static void test_faults_leave_out_the_salt(void **unused) {
    (void)unused;
    cdem_state s;
    double *v = graben(&s);
    cdem_faults_options o;
    cdem_faults_default_options(&o);
    cdem_faults_result plain, cover, all;
    cdem_error err;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &plain, &err), CDEM_OK);
    /* the salt: its elements' values replaced by a spread 3 +- 1 */
    size_t n_salt = 0;
    for (size_t i = 0; i < s.n; i++)
        if (cdem_surface_is_free(&s, i) && s.y[i] < 0.3 * H) {
            s.flags[i] |= CDEM_FLAG_SALT;
            v[i] = 3.0 + sin(0.37 * (double)i);
            n_salt++;
        }
    assert_true(n_salt > 100);
    assert_int_equal(cdem_faults_pick(&s, v, &o, &cover, &err), CDEM_OK);
    assert_int_equal(cover.n, plain.n); /* the same zones as without salt */
    assert_true(cover.n >= 1);
    assert_true(cover.threshold <= plain.threshold + 1e-12); /* the cover's field only */
    for (size_t k = 0; k < cover.n; k++) {
        assert_true(cover.zone[k].y_bottom >= 0.3 * H - 250.0); /* none inside the salt */
        assert_int_equal(cover.zone[k].dips_right, plain.zone[k].dips_right);
    }
    o.include_salt = 1;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &all, &err), CDEM_OK);
    /* the salt's strain counted: each of its rows is one pick, and they make a zone of
     * their own, inside the salt */
    assert_int_equal(all.n, cover.n + 1);
    int in_salt = 0;
    for (size_t k = 0; k < all.n; k++)
        in_salt += all.zone[k].y_top < 0.3 * H + 250.0;
    assert_int_equal(in_salt, 1);
    /* everything left out: the message says how to count the salt */
    for (size_t i = 0; i < s.n; i++)
        if (cdem_surface_is_free(&s, i))
            s.flags[i] |= CDEM_FLAG_SALT;
    o.include_salt = 0;
    cdem_faults_result none;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &none, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "salt elements left out: --include-salt"));
    cdem_faults_free(&plain);
    cdem_faults_free(&cover);
    cdem_faults_free(&all);
    free(v);
    cdem_state_free(&s);
}

/* The default model's graben (issue 35): a synthetic fault of total shear 2-8 and a weaker
 * antithetic one of 0.4-0.64 over a background of a few hundredths. The old default
 * threshold, a fixed 1, found only the synthetic one; the field's outlier bound finds both. */
static void test_faults_default_finds_a_weak_antithetic_fault(void **unused) {
    (void)unused;
    cdem_state s;
    make_packing(&s, 6000, W, H, 11);
    const double x0[2] = {3000.0, 10000.0}, dip[2] = {62.0, 51.0};
    const int right[2] = {1, 0};
    double *v = malloc(s.n * sizeof *v);
    assert_non_null(v);
    unsigned rng = 12345u;
    for (size_t i = 0; i < s.n; i++) {
        rng = rng * 1103515245u + 12345u;
        const double u = (double)(rng >> 8) / (double)(1u << 24);              /* 0..1 */
        v[i] = (s.flags[i] & CDEM_FLAGS_BOUNDARY) ? NAN : 0.01 + 0.06 * u * u; /* 0.01-0.07 */
        if (isnan(v[i]))
            continue;
        if (band_distance(s.x[i], s.y[i], x0[0], dip[0], right[0]) < 250.0)
            v[i] = 2.0 + 6.0 * u;
        else if (band_distance(s.x[i], s.y[i], x0[1], dip[1], right[1]) < 250.0)
            v[i] = 0.4 + 0.24 * u;
    }
    cdem_faults_options o;
    cdem_faults_default_options(&o);
    cdem_faults_result r;
    cdem_error err;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_OK);
    printf("    default threshold %.3g: %zu zones\n", r.threshold, r.n);
    assert_int_equal(r.n, 2);
    assert_true(r.threshold > 0.03 && r.threshold < 0.4); /* above most of the background */
    for (int b = 0; b < 2; b++) {
        assert_int_equal(r.zone[b].dips_right, right[b]);
        assert_true(fabs(r.zone[b].dip_deg - dip[b]) < 5.0);
        assert_true(fabs(r.zone[b].x_top - x0[b]) < 500.0);
    }
    cdem_faults_free(&r);
    /* the old default: the antithetic fault is lost */
    o.threshold = 1.0;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_OK);
    assert_int_equal(r.n, 1);
    cdem_faults_free(&r);
    free(v);
    cdem_state_free(&s);
}

static void test_faults_vertical_and_quiet(void **unused) {
    (void)unused;
    cdem_state s;
    make_packing(&s, 6000, W, H, 5);
    const double x0[1] = {6000.0}, dip[1] = {90.0};
    const int right[1] = {1};
    double *v = band_values(&s, 1, x0, dip, right);
    cdem_faults_options o;
    cdem_faults_default_options(&o);
    cdem_faults_result r;
    cdem_error err;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_OK);
    assert_int_equal(r.n, 1);
    assert_true(r.zone[0].dip_deg > 85.0);
    assert_true(fabs(r.zone[0].x_top - 6000.0) < 250.0);
    cdem_faults_free(&r);
    /* a threshold above every value finds nothing */
    o.threshold = 3.0;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_OK);
    assert_int_equal(r.n, 0);
    cdem_faults_free(&r);
    /* short zones do not count */
    o.threshold = 1.0;
    o.min_rows = 40;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_OK);
    assert_int_equal(r.n, 0);
    cdem_faults_free(&r);
    free(v);
    cdem_state_free(&s);
}

static void test_faults_errors(void **unused) {
    (void)unused;
    cdem_state s;
    make_packing(&s, 500, 3000.0, 2000.0, 7);
    double *v = malloc(s.n * sizeof *v);
    assert_non_null(v);
    for (size_t i = 0; i < s.n; i++)
        v[i] = NAN;
    cdem_faults_options o;
    cdem_faults_default_options(&o);
    cdem_faults_result r;
    cdem_error err;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "no free element has a value"));
    for (size_t i = 0; i < s.n; i++)
        v[i] = 0.0;
    o.threshold = -1.0;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "threshold -1 must be > 0 (or 0: from the field)"));
    /* the default on a uniform field: its outlier bound lies just above it, no zone */
    o.threshold = 0.0;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_OK);
    assert_int_equal(r.n, 0);
    assert_true(r.threshold > 0.0 && r.threshold < 1e-8);
    cdem_faults_free(&r);
    o.threshold = 1.0;
    o.min_rows = 1;
    assert_int_equal(cdem_faults_pick(&s, v, &o, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "min_rows 1"));
    assert_int_equal(r.n, 0);
    free(v);
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_faults_two_bands),
        cmocka_unit_test(test_faults_leave_out_the_salt),
        cmocka_unit_test(test_faults_default_finds_a_weak_antithetic_fault),
        cmocka_unit_test(test_faults_vertical_and_quiet),
        cmocka_unit_test(test_faults_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
