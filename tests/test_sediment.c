/* Tests of solver/sediment: the geometric deposit on a real assembly (only below sea level,
 * overlap-free, each disc resting on a support, new unique ids, layer/flags/born/mass right,
 * existing elements untouched), the sea-level formula and the event/settling schedule, the
 * cohesion made only for the deposit's pairs, growth layers never refined into flexural-slip
 * or layered classes, refused input by message, and a short end-to-end run that is
 * bit-identical when repeated, has settling increments, a sea level and growth elements, and
 * whose net displacement excludes the settling steps. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "assembly.h"
#include "h5format.h"
#include "integrate.h"
#include "bc.h"
#include "model.h"
#include "run.h"
#include "sediment.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cdem_params small_params(void) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.width = 10.0;
    p.height = 2.5;
    p.equilibration = 100.0;
    p.runtime = 160.0;
    p.display_interval = 0.5;
    p.series_interval = 50;
    p.sedimentation = 1;
    p.sea_level_rise = CDEM_SEA_MID;
    return p;
}

/* A built assembly with the sediment context of p. */
static void setup(const cdem_params *p, cdem_model *m, cdem_state *s, cdem_sediment *sd) {
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(p, m, &err), CDEM_OK);
    assert_int_equal(cdem_state_init(s, 1024, 0, &err), CDEM_OK);
    assert_int_equal(cdem_assembly_build(p, m, s, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_sediment_init(sd, p, m, &err), CDEM_OK);
}

static void test_sediment_deposit_below_sea_level_without_overlap(void **st) {
    (void)st;
    cdem_params p = small_params();
    cdem_model m;
    cdem_state s, before = {0};
    cdem_sediment sd;
    cdem_error err;
    setup(&p, &m, &s, &sd);
    assert_int_equal(cdem_state_copy(&before, &s, &err), CDEM_OK);
    const size_t n0 = s.n;
    const int32_t id0 = s.next_id;
    double top = -INFINITY, lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n0; i++)
        if (!(s.flags[i] & CDEM_FLAGS_BOUNDARY)) {
            top = fmax(top, s.y[i] + s.radius[i]);
            lo = fmin(lo, s.x[i] - s.radius[i]);
            hi = fmax(hi, s.x[i] + s.radius[i]);
        }
    const double rmax = m.radius[CDEM_NUM_RADII - 1];
    const double sea = top + 4.0 * rmax; /* about two rows of accommodation space */
    long added = 0;
    assert_int_equal(cdem_sediment_deposit(&sd, &s, sea, 25, 7, &added, &err), CDEM_OK);
    assert_true(added > 20);
    assert_int_equal(s.n, n0 + (size_t)added);
    /* the elements present before are untouched */
    for (size_t i = 0; i < n0; i++) {
        assert_true(s.x[i] == before.x[i] && s.y[i] == before.y[i]);
        assert_int_equal(s.id[i], before.id[i]);
        assert_int_equal(s.flags[i], before.flags[i]);
    }
    double highest = -INFINITY;
    for (size_t a = n0; a < s.n; a++) {
        /* below sea level, inside the free-element span, attributes of a growth element */
        assert_true(s.y[a] < sea);
        highest = fmax(highest, s.y[a]);
        assert_true(s.x[a] - s.radius[a] >= lo - 1e-9 && s.x[a] + s.radius[a] <= hi + 1e-9);
        assert_int_equal(s.layer[a], 25);
        assert_int_equal(s.flags[a], CDEM_FLAG_GROWTH);
        assert_int_equal(s.born[a], 7);
        assert_true(s.id[a] >= id0);
        int cls = -1;
        for (int k = 0; k < CDEM_NUM_RADII; k++)
            if (s.radius[a] == m.radius[k])
                cls = k;
        assert_true(cls >= 0);
        assert_true(s.mass[a] == m.mass[cls]);
        assert_true(s.vx[a] == 0.0 && s.vy[a] == 0.0);
        /* no overlap beyond the stated fraction, and resting on (touching) a support */
        double min_gap = INFINITY;
        for (size_t j = 0; j < s.n; j++) {
            if (j == a || (s.flags[j] & CDEM_FLAG_FOOTWALL))
                continue;
            const double d = hypot(s.x[j] - s.x[a], s.y[j] - s.y[a]);
            const double gap = d - (s.radius[a] + s.radius[j]);
            assert_true(gap >= -CDEM_SEDIMENT_OVERLAP_TOL * s.radius[a]);
            if (s.y[j] < s.y[a])
                min_gap = fmin(min_gap, gap);
            if (j > a)
                assert_int_not_equal(s.id[j], s.id[a]); /* ids unique */
        }
        assert_true(min_gap <= 1e-9 * s.radius[a]);
    }
    /* the space is filled up to sea level (within one largest diameter) */
    assert_true(highest > sea - 2.0 * rmax);
    assert_int_equal(sd.n_deposited, added);
    cdem_state_free(&before);
    cdem_state_free(&s);
    cdem_sediment_free(&sd);
    cdem_sediment_free(NULL);
}

/* The radius shares' stated sum (the deposits' draw and the assembly's bag use it as the
 * range and the bag size) is the sum of the shares. */
static void test_sediment_radius_shares_total(void **st) {
    (void)st;
    static const int shares[CDEM_NUM_RADII] = CDEM_RADIUS_SHARES;
    int sum = 0;
    for (int k = 0; k < CDEM_NUM_RADII; k++) {
        assert_true(shares[k] > 0);
        sum += shares[k];
    }
    assert_int_equal(sum, CDEM_RADIUS_SHARES_TOTAL);
}

static void test_sediment_deposit_is_deterministic(void **st) {
    (void)st;
    cdem_params p = small_params();
    cdem_model m;
    cdem_state s1, s2;
    cdem_sediment a, b;
    cdem_error err;
    setup(&p, &m, &s1, &a);
    setup(&p, &m, &s2, &b);
    long n1 = 0, n2 = 0;
    assert_int_equal(cdem_sediment_deposit(&a, &s1, 2600.0, 25, 3, &n1, &err), CDEM_OK);
    assert_int_equal(cdem_sediment_deposit(&b, &s2, 2600.0, 25, 3, &n2, &err), CDEM_OK);
    assert_true(n1 > 0);
    assert_int_equal(n1, n2);
    assert_memory_equal(s1.x, s2.x, s1.n * sizeof *s1.x);
    assert_memory_equal(s1.y, s2.y, s1.n * sizeof *s1.y);
    /* another seed gives another deposit */
    cdem_state s3;
    cdem_sediment c;
    p.seed += 1;
    setup(&p, &m, &s3, &c);
    long n3 = 0;
    assert_int_equal(cdem_sediment_deposit(&c, &s3, 2600.0, 25, 3, &n3, &err), CDEM_OK);
    assert_true(n3 != n1 || memcmp(s1.x, s3.x, s1.n * sizeof *s1.x) != 0);
    cdem_state_free(&s1);
    cdem_state_free(&s2);
    cdem_state_free(&s3);
    cdem_sediment_free(&a);
    cdem_sediment_free(&b);
    cdem_sediment_free(&c);
}

static void test_sediment_sea_level_and_schedule(void **st) {
    (void)st;
    cdem_params p = small_params();
    cdem_model m;
    cdem_state s;
    cdem_sediment sd;
    setup(&p, &m, &s, &sd);
    assert_true(isnan(cdem_sediment_sea_level(&sd, m.equil_steps)));
    assert_false(cdem_sediment_due(&sd, m.equil_steps + m.sediment_steps));
    cdem_sediment_begin(&sd, &s);
    double top = -INFINITY;
    for (size_t i = 0; i < s.n; i++)
        if (!(s.flags[i] & CDEM_FLAGS_BOUNDARY))
            top = fmax(top, s.y[i] + s.radius[i]);
    assert_true(cdem_sediment_sea_level(&sd, m.equil_steps) == top);
    const long k = 123;
    const double expect = top + (double)k * m.displacement_per_step * 0.5; /* mid = 0.5 */
    assert_float_equal(cdem_sediment_sea_level(&sd, m.equil_steps + k), expect, 1e-9 * expect);
    assert_true(isnan(cdem_sediment_sea_level(&sd, m.equil_steps - 1)));
    /* events every sediment_steps after equilibration, when the settling fits */
    const long e1 = m.equil_steps + m.sediment_steps;
    assert_true(m.settling_steps > 0 && m.settling_steps < m.sediment_steps);
    assert_true(e1 + m.settling_steps <= m.total_steps);
    assert_false(cdem_sediment_due(&sd, m.equil_steps));
    assert_false(cdem_sediment_due(&sd, e1 - 1));
    assert_true(cdem_sediment_due(&sd, e1));
    sd.total_steps = e1 + m.settling_steps - 1; /* settling would not fit: no event */
    assert_false(cdem_sediment_due(&sd, e1));
    sd.total_steps = m.total_steps;
    /* a settling window: (event, event + settling_steps] */
    sd.event_step = e1;
    sd.settle_end = e1 + m.settling_steps;
    assert_false(cdem_sediment_settling(&sd, e1));
    assert_true(cdem_sediment_settling(&sd, e1 + 1));
    assert_true(cdem_sediment_settling(&sd, e1 + m.settling_steps));
    assert_false(cdem_sediment_settling(&sd, e1 + m.settling_steps + 1));
    /* a disabled context answers nothing */
    cdem_sediment off;
    cdem_error err;
    p.sedimentation = 0;
    assert_int_equal(cdem_sediment_init(&off, &p, &m, &err), CDEM_OK);
    cdem_sediment_begin(&off, &s);
    assert_true(isnan(cdem_sediment_sea_level(&off, m.equil_steps + 10)));
    assert_false(cdem_sediment_due(&off, e1));
    assert_false(cdem_sediment_settling(&off, e1 + 1));
    cdem_sediment_free(&off);
    cdem_state_free(&s);
    cdem_sediment_free(&sd);
}

static void test_sediment_refuses_bad_input(void **st) {
    (void)st;
    cdem_params p = small_params();
    cdem_model m;
    cdem_state s;
    cdem_sediment sd;
    cdem_error err;
    setup(&p, &m, &s, &sd);
    long added = -1;
    assert_int_equal(cdem_sediment_deposit(&sd, &s, NAN, 25, 1, &added, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "sea level"));
    assert_int_equal(added, 0);
    cdem_state empty;
    assert_int_equal(cdem_state_init(&empty, 4, 0, &err), CDEM_OK);
    assert_int_equal(cdem_sediment_deposit(&sd, &empty, 10.0, 25, 1, &added, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "no free elements"));
    cdem_sediment off;
    p.sedimentation = 0;
    assert_int_equal(cdem_sediment_init(&off, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_sediment_deposit(&off, &s, 10.0, 25, 1, &added, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "sedimentation is off"));
    /* unusable model counts */
    p.sedimentation = 1;
    cdem_model bad = m;
    bad.sediment_steps = 0;
    cdem_sediment x;
    assert_int_equal(cdem_sediment_init(&x, &p, &bad, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "sediment_steps = 0"));
    cdem_sediment_free(&x);
    cdem_sediment_free(&off);
    cdem_state_free(&empty);
    cdem_state_free(&s);
    cdem_sediment_free(&sd);
}

/* Three touching pre-growth elements (layers 23, 24, 24) and one growth element of layer
 * 25 touching the top one: only the growth pair becomes cohesive; with flexural slip and
 * layered friction on, a growth pair is never flexural slip, and growth-growth pairs (or
 * growth with a non-layered layer) stay ordinary element-element pairs. */
static void test_sediment_cohesion_only_for_the_deposit(void **st) {
    (void)st;
    cdem_params p = small_params();
    p.flexural_slip = 1;
    p.layered_friction = 1;
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_state s;
    assert_int_equal(cdem_state_init(&s, 8, 0, &err), CDEM_OK);
    const double r = m.radius[1], d = 1.99 * r;
    size_t ix;
    assert_int_equal(cdem_state_append(&s, -1, 0.0, 0.0, r, m.mass[1], 23, 0, 0, &ix, &err),
                     CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, d, 0.0, r, m.mass[1], 24, 0, 0, &ix, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 2 * d, 0.0, r, m.mass[1], 24, 0, 0, &ix, &err),
                     CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, 2 * d, d, r, m.mass[1], 25, CDEM_FLAG_GROWTH, 5, &ix, &err),
        CDEM_OK);
    cdem_integrator it;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    long contacts = 0, bonds = 0;
    cdem_integrator_count(&it, &contacts, &bonds);
    assert_int_equal(contacts, 3);
    assert_int_equal(bonds, 0);
    assert_int_equal(cdem_sediment_make_cohesive(&it, &s, 26), 0); /* no such layer */
    assert_int_equal(cdem_sediment_make_cohesive(&it, &s, 25), 1);
    cdem_integrator_count(&it, &contacts, &bonds);
    assert_int_equal(bonds, 1);
    for (size_t q = 0; q < it.nb.np; q++) {
        const int32_t i = it.nb.pi[q], j = it.nb.pj[q];
        const int growth = s.layer[i] == 25 || s.layer[j] == 25;
        const int bonded = (it.nb.hist[q] & (CDEM_PAIR_COHESIVE | CDEM_PAIR_BONDED)) != 0;
        assert_int_equal(bonded, growth && (it.nb.hist[q] & CDEM_PAIR_TOUCH));
        if (growth) /* never flexural slip (layered here: the other element is layer 24) */
            assert_int_equal(it.nb.cls[q], CDEM_CLASS_LAYERED);
    }
    /* the refinement rule itself: growth layers are neither slip nor layered */
    assert_int_equal(cdem_contact_refine(&it.law, CDEM_CLASS_ELEMENT, 25, CDEM_FLAG_GROWTH, 26,
                                         CDEM_FLAG_GROWTH),
                     CDEM_CLASS_ELEMENT);
    assert_int_equal(cdem_contact_refine(&it.law, CDEM_CLASS_ELEMENT, 25, CDEM_FLAG_GROWTH, 12, 0),
                     CDEM_CLASS_ELEMENT);
    assert_int_equal(cdem_contact_refine(&it.law, CDEM_CLASS_ELEMENT, 23, 0, 24, 0),
                     CDEM_CLASS_SLIP);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

static cdem_status run_to(const cdem_params *p, const char *path, cdem_error *err) {
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    return cdem_run(p, &o, err);
}

static void test_sediment_end_to_end_reproducible(void **st) {
    (void)st;
    char pa[1024], pb[1024];
    scratch_path(pa, sizeof pa, "test_sediment_a.h5");
    scratch_path(pb, sizeof pb, "test_sediment_b.h5");
    cdem_params p = small_params();
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    /* at least one event whose settling ends before the run does */
    const long events = (m.total_steps - m.equil_steps - m.settling_steps) / m.sediment_steps;
    assert_true(events >= 1);
    if (run_to(&p, pa, &err) != CDEM_OK)
        fail_msg("run a: %s", err.msg);
    if (run_to(&p, pb, &err) != CDEM_OK)
        fail_msg("run b: %s", err.msg);
    cdem_h5_reader *ra = NULL, *rb = NULL;
    assert_int_equal(cdem_h5_reader_open(pa, &ra, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_open(pb, &rb, &err), CDEM_OK);
    const size_t ni = cdem_h5_reader_increment_count(ra);
    assert_int_equal(ni, cdem_h5_reader_increment_count(rb));
    cdem_state a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    cdem_increment_info ia, ib;
    int n_settling = 0;
    for (size_t k = 0; k < ni; k++) {
        assert_int_equal(cdem_h5_reader_load_increment(ra, k, &a, &ia, &err), CDEM_OK);
        assert_int_equal(cdem_h5_reader_load_increment(rb, k, &b, &ib, &err), CDEM_OK);
        assert_int_equal(a.n, b.n);
        assert_memory_equal(a.id, b.id, a.n * sizeof *a.id);
        assert_memory_equal(a.x, b.x, a.n * sizeof *a.x);
        assert_memory_equal(a.y, b.y, a.n * sizeof *a.y);
        assert_memory_equal(a.layer, b.layer, a.n * sizeof *a.layer);
        assert_memory_equal(a.born, b.born, a.n * sizeof *a.born);
        assert_memory_equal(&ia.net_displacement, &ib.net_displacement, sizeof(double));
        n_settling += ia.phase == CDEM_PHASE_SETTLING;
        if (ia.phase == CDEM_PHASE_EQUILIBRATION && ia.step < m.equil_steps)
            assert_true(isnan(ia.sea_level));
        else
            assert_true(isfinite(ia.sea_level));
    }
    assert_true(n_settling > 0);
    /* the last increment holds growth elements, deposited after equilibration */
    long growth = 0;
    for (size_t i = 0; i < a.n; i++) {
        if (!(a.flags[i] & CDEM_FLAG_GROWTH))
            continue;
        growth++;
        assert_true(a.layer[i] >= 25 && a.layer[i] < 25 + events);
        assert_true(a.born[i] > m.n_increments_equil);
    }
    assert_true(growth > 0);
    /* settling consumes runtime: the boundary moved only on the non-settling steps */
    assert_int_equal(ia.step, m.total_steps);
    const double net = (double)(m.total_steps - m.equil_steps - events * m.settling_steps) *
                       m.displacement_per_step;
    assert_float_equal(ia.net_displacement, net, 1e-6 * net);
    cdem_series_sample *ser = NULL;
    size_t ns = 0;
    assert_int_equal(cdem_h5_reader_read_series(ra, &ser, &ns, &err), CDEM_OK);
    assert_true(isnan(ser[0].sea_level));
    assert_true(isfinite(ser[ns - 1].sea_level));
    /* mid rise: the sea level rises from its first recorded value */
    size_t first = 0;
    while (first < ns && isnan(ser[first].sea_level))
        first++;
    assert_true(first < ns - 1);
    assert_true(ser[first].step >= m.equil_steps);
    assert_true(ser[ns - 1].sea_level > ser[first].sea_level);
    free(ser);
    cdem_state_free(&a);
    cdem_state_free(&b);
    cdem_h5_reader_close(ra);
    cdem_h5_reader_close(rb);
    remove(pa);
    remove(pb);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sediment_deposit_below_sea_level_without_overlap),
        cmocka_unit_test(test_sediment_radius_shares_total),
        cmocka_unit_test(test_sediment_deposit_is_deterministic),
        cmocka_unit_test(test_sediment_sea_level_and_schedule),
        cmocka_unit_test(test_sediment_refuses_bad_input),
        cmocka_unit_test(test_sediment_cohesion_only_for_the_deposit),
        cmocka_unit_test(test_sediment_end_to_end_reproducible),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
