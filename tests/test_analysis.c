/* test_analysis: the analysis context over in-memory increments: the incremental / total /
 * cumulative rules against analytical simple shear, growth elements against their birth
 * increment, removed elements, colour limits per quantity, stress, errors by message, and
 * thread-count invariance. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "assert_near.h"

#include "analysis.h"
#include "analysis_fixtures.h"

#include <math.h>
#include <omp.h>
#include <string.h>

#define NINC      12
#define EQUIL     3
#define GROWTH_AT 7
#define DGAMMA    0.01
#define LONE      99999 /* id of a free element far from all others */

typedef struct {
    cdem_state st[NINC];
    cdem_increment_info info[NINC];
    cdem_params params;
    cdem_analysis *a;
} fixture;

/* Increments 0..3 still (equilibration), then simple shear DGAMMA per increment about
 * y = 0; at GROWTH_AT a layer of growth elements is added on top; at 9 element id 5 is
 * removed; increments 4..11 store stress sxx = 1e6 * id (id 0 also 1e9, to test the cap). */
static int setup(void **state) {
    fixture *f = calloc(1, sizeof *f);
    cdem_error err;
    make_packing(&f->st[0], 250, 3600.0, 1600.0, 17);
    /* a lone free element far from the others: never enough neighbours */
    cdem_state_append(&f->st[0], LONE, 60000.0, 500.0, 50, 1, 3, 0, 0, NULL, &err);
    f->st[0].next_id = 100000;
    for (int k = 0; k < NINC; k++) {
        if (k > 0)
            cdem_state_copy(&f->st[k], &f->st[k - 1], &err);
        if (k > EQUIL) {
            const double F[4] = {1, DGAMMA, 0, 1};
            deform_affine(&f->st[k], F, 0, 0);
        }
        if (k == GROWTH_AT) {
            for (double x = 100; x < 3500; x += 180)
                cdem_state_append(&f->st[k], -1, x, 1700.0, 60, 1, 25, CDEM_FLAG_GROWTH, GROWTH_AT,
                                  NULL, &err);
            for (double x = 190; x < 3500; x += 180)
                cdem_state_append(&f->st[k], -1, x, 1856.0, 60, 1, 25, CDEM_FLAG_GROWTH, GROWTH_AT,
                                  NULL, &err);
        }
        if (k == 9) {
            unsigned char *keep = malloc(f->st[k].n);
            for (size_t i = 0; i < f->st[k].n; i++)
                keep[i] = f->st[k].id[i] != 5;
            cdem_state_compact(&f->st[k], keep, NULL);
            free(keep);
        }
        if (k > EQUIL) {
            cdem_state_enable_stress(&f->st[k], &err);
            for (size_t i = 0; i < f->st[k].n; i++) {
                f->st[k].sxx[i] = f->st[k].id[i] == 0 ? 1e9 : 1e6 * f->st[k].id[i];
                f->st[k].syy[i] = 2e6;
                f->st[k].sxy[i] = 0.0;
            }
        }
        f->info[k].number = k;
        f->info[k].phase = k <= EQUIL ? CDEM_PHASE_EQUILIBRATION : CDEM_PHASE_DEFORMATION;
        f->info[k].has_stress = k > EQUIL;
        f->info[k].n_elements = (int64_t)f->st[k].n;
    }
    cdem_params_defaults(&f->params);
    f->params.total_strain_max = 1.5;
    assert_int_equal(cdem_analysis_open_states(f->st, f->info, NINC, &f->params, &f->a, &err),
                     CDEM_OK);
    *state = f;
    return 0;
}

static int teardown(void **state) {
    fixture *f = *state;
    cdem_analysis_close(f->a);
    for (int k = 0; k < NINC; k++)
        cdem_state_free(&f->st[k]);
    free(f);
    return 0;
}

static const cdem_quantity *Q(const char *name) {
    const cdem_quantity *q;
    cdem_error err;
    assert_int_equal(cdem_quantity_find(name, &q, &err), CDEM_OK);
    return q;
}

static double shear_of(double g) {
    return g * sqrt(1.0 + g * g / 4.0);
}

static void test_analysis_total_and_incremental_rules(void **state) {
    fixture *f = *state;
    cdem_error err;
    const cdem_state *s;
    double *v;
    assert_int_equal(cdem_analysis_equil_index(f->a), EQUIL);
    /* total: NaN during equilibration */
    assert_int_equal(cdem_analysis_values(f->a, 2, Q("total-max-shear"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        assert_true(isnan(v[i]));
    free(v);
    /* total at 11: shear 8 * DGAMMA for pre-growth, 4 * DGAMMA for growth (born at 7) */
    assert_int_equal(cdem_analysis_values(f->a, 11, Q("total-max-shear"), &s, &v, &err), CDEM_OK);
    size_t pre = 0, growth = 0;
    for (size_t i = 0; i < s->n; i++) {
        if ((s->flags[i] & CDEM_FLAG_WALL) || s->id[i] == LONE) {
            assert_true(isnan(v[i])); /* walls, and the lone element (too few neighbours) */
        } else if (s->flags[i] & CDEM_FLAG_GROWTH) {
            if (isnan(v[i]))
                continue; /* growth elements too isolated to fit */
            assert_near(v[i], shear_of(4 * DGAMMA), 1e-12);
            growth++;
        } else {
            assert_near(v[i], shear_of(8 * DGAMMA), 1e-12);
            pre++;
        }
    }
    assert_true(pre > 150 && growth > 30);
    free(v);
    /* total-disp-x of a pre-growth element: gamma * y(equil) */
    assert_int_equal(cdem_analysis_values(f->a, 11, Q("total-disp-x"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == 7)
            assert_near(v[i], 8 * DGAMMA * f->st[EQUIL].y[7], 1e-9);
    free(v);
    /* incremental at 10: against 5, shear 5 * DGAMMA; at 2 (< 5): against 0, zero */
    assert_int_equal(cdem_analysis_values(f->a, 10, Q("incr-max-shear"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY) && !(s->flags[i] & CDEM_FLAG_GROWTH) &&
            s->id[i] != LONE)
            assert_near(v[i], shear_of(5 * DGAMMA), 1e-12);
    free(v);
    assert_int_equal(cdem_analysis_values(f->a, 10, Q("incr-rotation"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY) && !(s->flags[i] & CDEM_FLAG_GROWTH) &&
            s->id[i] != LONE)
            assert_near(v[i], 5 * DGAMMA / 2, 1e-12); /* top to the right: clockwise */
    free(v);
    /* S1 direction of simple shear 0.05 (deformed frame): 0.5 atan2(2 g, g^2) */
    assert_int_equal(cdem_analysis_values(f->a, 10, Q("incr-s1-direction"), &s, &v, &err), CDEM_OK);
    const double g5 = 5 * DGAMMA, a5 = 0.5 * atan2(2 * g5, g5 * g5) * 180 / M_PI;
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY) && !(s->flags[i] & CDEM_FLAG_GROWTH) &&
            s->id[i] != LONE)
            assert_near(v[i], a5, 1e-8);
    free(v);
    assert_int_equal(cdem_analysis_values(f->a, 2, Q("incr-disp-mag"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        assert_near(v[i], 0.0, 0);
    free(v);
    /* the removed element is absent from increment 9 on */
    assert_int_equal(cdem_analysis_values(f->a, 9, Q("total-e1"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        assert_int_not_equal(s->id[i], 5);
    assert_int_equal(s->n, f->st[9].n);
    free(v);
}

static void test_analysis_cumulative_sums_pairs(void **state) {
    fixture *f = *state;
    cdem_error err;
    const cdem_state *s;
    double *v, *w;
    /* forward to 10, then back to 6: each must equal the sum of its pairs */
    const size_t ks[3] = {10, 6, EQUIL};
    for (int t = 0; t < 3; t++) {
        size_t k = ks[t];
        assert_int_equal(cdem_analysis_values(f->a, k, Q("cum-max-shear"), &s, &v, &err), CDEM_OK);
        for (size_t i = 0; i < s->n; i++)
            if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY) && !(s->flags[i] & CDEM_FLAG_GROWTH) &&
                s->id[i] != LONE)
                assert_near(v[i], (double)(k - EQUIL) * shear_of(DGAMMA), 1e-12);
        free(v);
    }
    /* the lone element: 0 at the end of equilibration, NaN afterwards (never zero) */
    for (int t = 0; t < 2; t++) {
        size_t k = t == 0 ? EQUIL : 8;
        assert_int_equal(cdem_analysis_values(f->a, k, Q("cum-e1"), &s, &v, &err), CDEM_OK);
        for (size_t i = 0; i < s->n; i++)
            if (s->id[i] == LONE) {
                if (t == 0)
                    assert_true(v[i] == 0.0);
                else
                    assert_true(isnan(v[i]));
            }
        free(v);
    }
    /* cumulative differs from total once the path is not coaxial: here they agree to
     * first order only (sum of pair shears vs shear of the sum) */
    assert_int_equal(cdem_analysis_values(f->a, 11, Q("cum-max-shear"), &s, &v, &err), CDEM_OK);
    double cum = NAN;
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == 7)
            cum = v[i];
    free(v);
    assert_near(cum, 8 * shear_of(DGAMMA), 1e-12);
    assert_true(fabs(cum - shear_of(8 * DGAMMA)) > 1e-7);
    /* thread-count invariance, bit for bit */
    omp_set_num_threads(1);
    cdem_analysis_close(f->a);
    cdem_analysis_open_states(f->st, f->info, NINC, &f->params, &f->a, &err);
    assert_int_equal(cdem_analysis_values(f->a, 11, Q("cum-dilation"), &s, &v, &err), CDEM_OK);
    omp_set_num_threads(2);
    cdem_analysis_close(f->a);
    cdem_analysis_open_states(f->st, f->info, NINC, &f->params, &f->a, &err);
    assert_int_equal(cdem_analysis_values(f->a, 11, Q("cum-dilation"), &s, &w, &err), CDEM_OK);
    assert_memory_equal(v, w, s->n * sizeof *v);
    free(v);
    free(w);
}

/* A source over the fixture that counts loads. */
typedef struct {
    fixture *f;
    size_t loads;
} counting;
static size_t cnt_count(void *ctx) {
    (void)ctx;
    return NINC;
}
static cdem_status cnt_info(void *ctx, size_t index, cdem_increment_info *info, cdem_error *err) {
    (void)err;
    *info = ((counting *)ctx)->f->info[index];
    return CDEM_OK;
}
static cdem_status cnt_load(void *ctx, size_t index, cdem_state *s, cdem_error *err) {
    counting *c = ctx;
    c->loads++;
    return cdem_state_copy(s, &c->f->st[index], err);
}

static void test_analysis_cumulative_reuses_pairs(void **state) {
    fixture *f = *state;
    counting c = {f, 0};
    const cdem_analysis_source ops = {cnt_count, cnt_info, cnt_load, NULL, NULL};
    cdem_analysis *a;
    cdem_error err;
    assert_int_equal(cdem_analysis_open_source(&ops, &c, &f->params, &a, &err), CDEM_OK);
    /* walking every increment forward loads each increment about once (LRU of 4 slots):
     * pairs are computed once and the running sums reused, never recomputed from the start */
    for (size_t k = 0; k < NINC; k++) {
        const cdem_state *s;
        double *v;
        assert_int_equal(cdem_analysis_values(a, k, Q("cum-max-shear"), &s, &v, &err), CDEM_OK);
        free(v);
    }
    assert_true(c.loads <= NINC + 2);
    cdem_analysis_close(a);
}

static void test_analysis_limits_per_quantity(void **state) {
    fixture *f = *state;
    cdem_error err;
    cdem_limits l;
    assert_int_equal(cdem_analysis_limits(f->a, 8, Q("incr-max-shear"), &l, &err), CDEM_OK);
    assert_true(l.vmin == 0.0 && l.vmax == 0.1);
    assert_int_equal(cdem_analysis_limits(f->a, 8, Q("incr-rotation"), &l, &err), CDEM_OK);
    assert_true(l.vmin == -0.1 && l.vmax == 0.1);
    assert_int_equal(cdem_analysis_limits(f->a, 8, Q("total-e1"), &l, &err), CDEM_OK);
    assert_true(l.vmin == 0.0 && l.vmax == 1.5); /* total_strain_max of the run */
    assert_int_equal(cdem_analysis_limits(f->a, 8, Q("cum-dilation"), &l, &err), CDEM_OK);
    assert_true(l.vmin == -1.5 && l.vmax == 1.5);
    assert_near(l.threshold, 0.15, 1e-15);
    /* incremental displacement: percentiles of the current increment's free elements */
    const cdem_state *s;
    double *v;
    assert_int_equal(cdem_analysis_values(f->a, 8, Q("incr-disp-x"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            v[i] = NAN;
    cdem_limits want;
    cdem_limits_from_values(v, s->n, 0.01, 0.99, 0, 0, &want, &err);
    free(v);
    assert_int_equal(cdem_analysis_limits(f->a, 8, Q("incr-disp-x"), &l, &err), CDEM_OK);
    assert_near(l.vmin, want.vmin, 0);
    assert_near(l.vmax, want.vmax, 0);
    assert_true(l.vmax > 0.04 * 1000); /* 5 * DGAMMA * y reaches tens of metres */
    /* total displacement limits: from the last increment, the same for any increment */
    cdem_limits l2;
    assert_int_equal(cdem_analysis_limits(f->a, 4, Q("total-disp-x"), &l, &err), CDEM_OK);
    assert_int_equal(cdem_analysis_limits(f->a, 11, Q("total-disp-x"), &l2, &err), CDEM_OK);
    assert_true(l.vmin == l2.vmin && l.vmax == l2.vmax && l.vmax > 0.0);
    /* uplift: signed, symmetric */
    assert_int_equal(cdem_analysis_limits(f->a, 11, Q("uplift"), &l, &err), CDEM_OK);
    assert_true(l.vmin == -l.vmax);
    /* stress over all increments, capped at 200e6 (sxx = 1e6 id, id 0 = 1e9) */
    assert_int_equal(cdem_analysis_limits(f->a, 5, Q("sxx"), &l, &err), CDEM_OK);
    assert_true(l.vmax <= 200e6 && l.vmax > 100e6);
    assert_true(l.vmin >= 1e6 && l.vmin < 5e6);
}

static void test_analysis_stress_and_errors(void **state) {
    fixture *f = *state;
    cdem_error err;
    const cdem_state *s;
    double *v;
    assert_int_equal(cdem_analysis_values(f->a, 6, Q("sigma3"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == 0)
            assert_near(v[i], 2e6, 0);
        else if (s->id[i] == 10)
            assert_near(v[i], 2e6, 0); /* sxx = 10e6 > syy */
    free(v);
    /* sigma1 direction: sxx = 1e6 id against syy = 2e6, no shear */
    assert_int_equal(cdem_analysis_values(f->a, 6, Q("sigma1-direction"), &s, &v, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++) {
        if (s->id[i] == 1)
            assert_near(v[i], 90.0, 1e-12);
        else if (s->id[i] == 2)
            assert_true(isnan(v[i])); /* isotropic: no direction */
        else if (s->id[i] > 2 && s->id[i] < 1000)
            assert_near(v[i], 0.0, 1e-12);
    }
    free(v);
    cdem_limits l;
    assert_int_equal(cdem_analysis_limits(f->a, 6, Q("sigma1-direction"), &l, &err), CDEM_OK);
    assert_true(l.vmin == -90.0 && l.vmax == 90.0);
    assert_int_equal(cdem_analysis_values(f->a, 2, Q("sxx"), &s, &v, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "increment 2 stores none"));
    assert_null(v);
    size_t idx;
    assert_int_equal(cdem_analysis_find(f->a, "999", &idx, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "increment 999 does not exist (the run has 0..11)"));
    assert_int_equal(cdem_analysis_find(f->a, "abc", &idx, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "'abc'"));
    assert_int_equal(cdem_analysis_find(f->a, "equil", &idx, &err), CDEM_OK);
    assert_int_equal(idx, EQUIL);
    assert_int_equal(cdem_analysis_find(f->a, "last", &idx, &err), CDEM_OK);
    assert_int_equal(idx, NINC - 1);
    const cdem_quantity *q;
    assert_int_equal(cdem_quantity_find("total-max-sheer", &q, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "did you mean 'total-max-shear'"));
    assert_non_null(strstr(err.msg, "max-shear-stress"));
    assert_int_equal(cdem_analysis_values(f->a, 99, Q("sxx"), &s, &v, &err), CDEM_ERR_NOTFOUND);
}

static void test_analysis_vectors_and_axes(void **state) {
    fixture *f = *state;
    cdem_error err;
    const cdem_state *s;
    double *ux, *uy;
    assert_int_equal(cdem_analysis_vectors(f->a, 11, 1, &s, &ux, &uy, &err), CDEM_OK);
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == 7) {
            assert_near(ux[i], 8 * DGAMMA * f->st[EQUIL].y[7], 1e-9);
            assert_near(uy[i], 0.0, 1e-9);
        }
    free(ux);
    free(uy);
    cdem_axes ax;
    assert_int_equal(cdem_analysis_axes(f->a, 11, CDEM_AXES_TOTAL_STRAIN, &ax, &err), CDEM_OK);
    assert_true(ax.n > 20);
    /* simple shear 0.08, top to the right: S1 at 0.5 atan2(2g, g^2) from +x */
    const double g = 8 * DGAMMA, want = 0.5 * atan2(2 * g, g * g) * 180 / M_PI;
    size_t ok = 0;
    for (size_t k = 0; k < ax.n; k++)
        ok += fabs(ax.angle1[k] - want) < 1e-6;
    assert_true(ok > ax.n * 9 / 10); /* nodes near growth elements mix references */
    cdem_axes_free(&ax);
    assert_int_equal(cdem_analysis_axes(f->a, 2, CDEM_AXES_TOTAL_STRAIN, &ax, &err), CDEM_OK);
    assert_int_equal(ax.n, 0);
    assert_int_equal(cdem_analysis_axes(f->a, 2, CDEM_AXES_STRESS, &ax, &err), CDEM_ERR_INVALID);
    assert_int_equal(cdem_analysis_axes(f->a, 6, CDEM_AXES_STRESS, &ax, &err), CDEM_OK);
    assert_true(ax.n > 0);
    cdem_axes_free(&ax);
}

/* The quantities not checked above, on the same simple shear: with F = [1 g; 0 1] the
 * principal stretches are S1 = sqrt(1 + g^2/4) + g/2 and S3 = sqrt(1 + g^2/4) - g/2
 * (S1 S3 = det F = 1: no dilation), S1 at 0.5 atan2(2 g, g^2) from +x. */
static void test_analysis_remaining_quantities(void **state) {
    fixture *f = *state;
    static const struct {
        const char *name;
        size_t k;     /* increment */
        int kind;     /* 0: S1 - 1, 1: 1 - S3, 2: zero, 3: S1 direction, 4: |u| = |ux| */
        double gamma; /* the shear of the pair (for cum-: of each of its k - EQUIL pairs) */
        double times; /* how many pairs add up (1 but for cum-) */
    } cases[] = {
        {"incr-e1", 10, 0, 5 * DGAMMA, 1},        {"incr-e3", 10, 1, 5 * DGAMMA, 1},
        {"incr-disp-y", 10, 2, 5 * DGAMMA, 1},    {"total-e3", 11, 1, 8 * DGAMMA, 1},
        {"total-dilation", 11, 2, 8 * DGAMMA, 1}, {"total-s1-direction", 11, 3, 8 * DGAMMA, 1},
        {"cum-e3", 11, 1, DGAMMA, 11 - EQUIL},    {"total-disp-mag", 11, 4, 8 * DGAMMA, 1},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        cdem_error err;
        const cdem_state *s;
        double *v, *ux = NULL;
        const double g = cases[c].gamma, r = sqrt(1.0 + g * g / 4.0);
        double want = 0.0;
        if (cases[c].kind == 0)
            want = cases[c].times * (r + g / 2 - 1.0);
        else if (cases[c].kind == 1)
            want = cases[c].times * (1.0 - (r - g / 2));
        else if (cases[c].kind == 3)
            want = 0.5 * atan2(2 * g, g * g) * 180 / M_PI;
        if (cases[c].kind == 4) {
            assert_int_equal(
                cdem_analysis_values(f->a, cases[c].k, Q("total-disp-x"), &s, &ux, &err), CDEM_OK);
        }
        assert_int_equal(cdem_analysis_values(f->a, cases[c].k, Q(cases[c].name), &s, &v, &err),
                         CDEM_OK);
        size_t checked = 0;
        for (size_t i = 0; i < s->n; i++) {
            if ((s->flags[i] & CDEM_FLAGS_BOUNDARY) || (s->flags[i] & CDEM_FLAG_GROWTH) ||
                s->id[i] == LONE)
                continue;
            if (cases[c].kind == 4)
                want = fabs(ux[i]);
            if (fabs(v[i] - want) > 1e-8)
                fail_msg("%s of element %d: %.17g, want %.17g", cases[c].name, (int)s->id[i], v[i],
                         want);
            checked++;
        }
        assert_true(checked > 150);
        free(v);
        free(ux);
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_analysis_total_and_incremental_rules, setup, teardown),
        cmocka_unit_test_setup_teardown(test_analysis_cumulative_sums_pairs, setup, teardown),
        cmocka_unit_test_setup_teardown(test_analysis_remaining_quantities, setup, teardown),
        cmocka_unit_test_setup_teardown(test_analysis_cumulative_reuses_pairs, setup, teardown),
        cmocka_unit_test_setup_teardown(test_analysis_limits_per_quantity, setup, teardown),
        cmocka_unit_test_setup_teardown(test_analysis_stress_and_errors, setup, teardown),
        cmocka_unit_test_setup_teardown(test_analysis_vectors_and_axes, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
