/* The tests' law with a coefficient and a history slot of its own
 * (common/laws/law_test_slip_weakening.h): strength mu Fn + max(0, k C0 - S), S the contact's
 * accumulated slip in its slot, k = material.test_slip_cohesion_share. It is registered by its
 * file and its line in laws.def alone; these tests show that the machinery gives it its
 * coefficient from its parameter row and keeps its slot: through the contact kernel against
 * a hand-computed loading history, through list rebuilds (re-sorting, element removal) and
 * through a checkpoint (a resumed run is bit-identical; a run that lost the slots is not). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "checkpoint.h"
#include "integrate.h"
#include "law_fixtures.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The fixture contact of law_fixtures.h (Kn = Ks = 1e9 N/m, Fn = 1e6 N, mu 0.25, C0 = 5e8 N)
 * under the law with coefficient k (NULL: the row's default), through the parameter row; the
 * cohesion is not lost at the first slip (only the slot wears it). */
static cdem_contact_law slip_law(const char *k) {
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    p.granular_law = CDEM_LAW_TEST_SLIP_WEAKENING;
    p.element.friction = LAW_FX_MU;
    p.element.cohesion = LAW_FX_C0;
    p.first_slip = 0;
    if (k) {
        char text[96];
        snprintf(text, sizeof text, "material.test_slip_cohesion_share=%s", k);
        assert_int_equal(cdem_params_override(&p, text, &err), CDEM_OK);
    }
    cdem_contact_law law;
    assert_int_equal(cdem_contact_law_init(&law, &p, 1e9, 1e9, &err), CDEM_OK);
    assert_int_equal(law.coefficient_count, 1);
    assert_int_equal(law.slot_count, 1);
    return law;
}

/* One step of the fixture contact (i at the origin, j at (1.999, 0), t = (0, 1)) with the
 * tangential increment d (m; dt = 1 s); returns the tangential force. */
static double step(const cdem_contact_law *law, double d, double *xs, uint8_t *hist, double *S) {
    double fx = 0.0, fy = 0.0;
    cdem_contact_touching(law, CDEM_CLASS_ELEMENT, 1.999 * 1.999, 1.999, 0.0, 2.0, 0.0, d, 1.0, xs,
                          hist, S, &fx, &fy);
    return fy;
}

#define NEAR(a, b) (fabs((a) - (b)) <= 1e-3) /* N: Fn is 1e6 to the rounding of the distance */

/* slip-1: a loading history by hand. k = 0.75, mu Fn = 2.5e5 N, k C0 = 3.75e8 N:
 *   d = 0.5   spring 5e8 > 3.7525e8: slips, S = 1.2475e8, force 3.7525e8
 *   d = 0.2   spring 5.7525e8 > 2.5e5 + (3.75e8 - 1.2475e8) = 2.505e8: slips,
 *             S = 1.2475e8 + 3.2475e8 = 4.495e8, force 2.505e8
 *   d = -0.3  spring -4.95e7, the cohesion worn out (S > k C0): limit 2.5e5, slips backwards,
 *             S = 4.495e8 + 4.925e7 = 4.9875e8, force -2.5e5
 *   d = 1e-4  spring -1.5e5 within the limit: no slip, S kept
 * Then the pair separates, which sets its slot back to 0 with Xs, and touches again: a new
 * contact, which does not slip at 1e8 (with S kept its limit would be 2.5e5). */
static void test_law_test_slip_weakening_history_by_hand(void **state) {
    (void)state;
    const cdem_contact_law law = slip_law(NULL); /* k = 0.75, the row's default */
    assert_true(law.coef[0] == 0.75);
    double xs = 0.0, S = 0.0;
    uint8_t hist = CDEM_PAIR_TOUCH | CDEM_PAIR_COHESIVE;
    double f = step(&law, 0.5, &xs, &hist, &S);
    assert_true(NEAR(f, 3.7525e8) && NEAR(S, 1.2475e8));
    f = step(&law, 0.2, &xs, &hist, &S);
    assert_true(NEAR(f, 2.505e8) && NEAR(S, 4.495e8));
    f = step(&law, -0.3, &xs, &hist, &S);
    assert_true(NEAR(f, -2.5e5) && NEAR(S, 4.9875e8));
    f = step(&law, 1e-4, &xs, &hist, &S);
    assert_true(NEAR(f, -1.5e5) && NEAR(S, 4.9875e8));
    assert_true(hist & CDEM_PAIR_COHESIVE); /* first_slip off: cohesion only worn by S */
    /* separated (r > R), then touching again as a new contact */
    double fx, fy;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, 2.1, 0.0, 2.0, 0.0, 0.0, 1.0, &xs, &hist, &S, &fx,
                      &fy);
    assert_true(hist == 0 && xs == 0.0 && S == 0.0); /* the contact's history is gone */
    cdem_contact_law formed = law;
    formed.cohesive_new = 1; /* a contact that forms is cohesive (cohesive_contacts = formed) */
    f = step(&formed, 0.1, &xs, &hist, &S);
    assert_true(NEAR(f, 1e8) && S == 0.0);
}

/* slip-2: the coefficient comes from its parameter row and changes the result as the formula
 * says: with k = 0.25 the first step slips at mu Fn + k C0 = 1.2525e8, S = 3.7475e8; with
 * k = 1 it does not slip (limit 5.0025e8 > 5e8). The row is a fixture's: it is found and
 * range-checked but not listed. */
static void test_law_test_slip_weakening_coefficient(void **state) {
    (void)state;
    const double k_values[2] = {0.25, 1.0};
    const char *k_words[2] = {"0.25", "1"};
    const double force[2] = {1.2525e8, 5e8}, slip[2] = {3.7475e8, 0.0};
    for (int c = 0; c < 2; c++) {
        const cdem_contact_law law = slip_law(k_words[c]);
        assert_true(law.coef[0] == k_values[c]);
        double xs = 0.0, S = 0.0;
        uint8_t hist = CDEM_PAIR_TOUCH | CDEM_PAIR_COHESIVE;
        const double f = step(&law, 0.5, &xs, &hist, &S);
        if (!(NEAR(f, force[c]) && NEAR(S, slip[c])))
            fail_msg("k = %g: force %.17g, S %.17g; expected %.17g, %.17g", k_values[c], f, S,
                     force[c], slip[c]);
    }
    const cdem_param_def *row = cdem_params_find("material", "test_slip_cohesion_share");
    assert_non_null(row);
    assert_true(row->fixture);
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    assert_int_equal(cdem_params_override(&p, "material.test_slip_cohesion_share=1.5", &err),
                     CDEM_ERR_RANGE);
    /* no parameter file can choose the law */
    assert_true(CDEM_LAW_TEST_SLIP_WEAKENING >= CDEM_LAW_WORDS);
    assert_int_equal(cdem_params_override(&p, "material.granular_law=test-slip-weakening", &err),
                     CDEM_ERR_RANGE);
}

/* ---------------------------------------------------------------- in a run */

#define KN  1.544871985e9
#define RHO 2500.0
#define DT  0.028

static double disc_mass(double r) {
    return RHO * M_PI * r * r;
}

static double rnd(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

/* 8 x 6 elements falling into a box of walls, with random velocities of up to 3 m/s. */
static void make_pile(cdem_state *s) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, 200, 0, &err), CDEM_OK);
    const double sp = 199.0, rw = 50.0, width = 10 * sp;
    for (double x = 0.0; x <= width + 1e-9; x += rw)
        assert_int_equal(
            cdem_state_append(s, -1, x, 0.0, rw, disc_mass(rw), 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
    for (double y = rw; y <= 8 * sp; y += rw)
        for (int side = 0; side < 2; side++)
            assert_int_equal(cdem_state_append(s, -1, side * width, y, rw, disc_mass(rw), 0,
                                               CDEM_FLAG_WALL, 0, NULL, &err),
                             CDEM_OK);
    uint64_t g = 45;
    for (int j = 0; j < 6; j++)
        for (int i = 0; i < 8; i++) {
            const double rad = 100.0 - 5.0 * rnd(&g);
            size_t k;
            assert_int_equal(cdem_state_append(s, -1, sp + i * sp + (j % 2) * 0.5 * sp,
                                               150.0 + j * sp * 0.8660254037844386, rad,
                                               disc_mass(rad), 1, 0, 0, &k, &err),
                             CDEM_OK);
            s->vx[k] = (rnd(&g) - 0.5) * 6.0;
            s->vy[k] = (rnd(&g) - 0.5) * 6.0;
        }
}

/* An integrator for the pile under the law with coefficient k: every contact that forms is
 * cohesive (C0 = 1e8 N) and loses its cohesion only as its slot wears it. */
static void start(cdem_integrator *it, double k) {
    cdem_model m;
    memset(&m, 0, sizeof m);
    const double r[4] = {50.0, 75.0, 100.0, 125.0};
    for (int c = 0; c < 4; c++) {
        m.radius[c] = r[c];
        m.mass[c] = disc_mass(r[c]);
    }
    m.min_mass = m.mass[0];
    m.max_radius = 125.0;
    m.average_radius = 87.5;
    m.kn = m.ks = KN;
    m.dt = DT;
    m.damping = DT * 3.0e9;
    m.gravity = 9.81;
    cdem_params p;
    cdem_params_defaults(&p);
    p.material = CDEM_MATERIAL_GRANULAR;
    p.granular_law = CDEM_LAW_TEST_SLIP_WEAKENING;
    p.cohesive_contacts = CDEM_COHESIVE_FORMED;
    p.first_slip = 0;
    p.element = (cdem_contact_material){.friction = 0.25, .cohesion = 1e8, .breaking_strain = 1.0};
    p.wall = p.element;
    p.fault = p.element;
    p.base = p.element;
    p.test_slip_cohesion_share = k;
    cdem_error err;
    assert_int_equal(cdem_integrator_init(it, &p, &m, &err), CDEM_OK);
    assert_int_equal(it->nb.slot_count, 1);
}

static void run(cdem_integrator *it, cdem_state *s, int steps) {
    cdem_error err;
    for (int k = 0; k < steps; k++)
        assert_int_equal(cdem_integrator_step(it, s, NULL, 0, 0.0, &err), CDEM_OK);
}

/* The touching pairs of the list, by element-id key, with their slots. */
typedef struct {
    uint64_t key;
    double S;
} keyed_slot;

static size_t touching_slots(const cdem_integrator *it, const cdem_state *s, keyed_slot *out) {
    size_t n = 0;
    for (size_t p = 0; p < it->nb.np; p++)
        if (it->nb.hist[p] & CDEM_PAIR_TOUCH)
            out[n++] = (keyed_slot){cdem_pair_key(s->id[it->nb.pi[p]], s->id[it->nb.pj[p]]),
                                    it->nb.slots[p]};
    return n;
}

/* slip-3: after a run in which contacts slid, a list rebuild that re-sorts the elements and one
 * that removes an element keep every touching pair's slot, bit for bit, by its element ids. */
static void test_law_test_slip_weakening_slot_survives_rebuild(void **state) {
    (void)state;
    cdem_state s;
    cdem_integrator it;
    cdem_error err;
    make_pile(&s);
    start(&it, 0.75);
    run(&it, &s, 200);
    keyed_slot *before = malloc(it.nb.np * sizeof *before), *after = NULL;
    const size_t n = touching_slots(&it, &s, before);
    size_t slid = 0;
    for (size_t q = 0; q < n; q++)
        slid += before[q].S > 0.0;
    if (slid < 10)
        fail_msg("%zu of %zu contacts slid: too few to test the slot", slid, n);
    /* a re-sort: the indices change, the slots follow the ids */
    assert_int_equal(cdem_neighbour_build(&it.nb, &s, NULL, 1, &err), CDEM_OK);
    unsigned char *keep = malloc(s.n);
    memset(keep, 1, s.n);
    int32_t removed = -1;
    for (size_t i = 0; i < s.n && removed < 0; i++)
        if (!(s.flags[i] & CDEM_FLAGS_BOUNDARY))
            removed = s.id[i];
    for (size_t i = 0; i < s.n; i++)
        keep[i] = s.id[i] != removed;
    /* and a removal */
    assert_int_equal(cdem_neighbour_build(&it.nb, &s, keep, 0, &err), CDEM_OK);
    after = malloc(it.nb.np * sizeof *after);
    const size_t m = touching_slots(&it, &s, after);
    size_t found = 0, gone = 0;
    for (size_t q = 0; q < n; q++) {
        const uint64_t key = before[q].key;
        if ((int32_t)(key >> 32) == removed || (int32_t)(key & 0xffffffffu) == removed) {
            gone++;
            continue;
        }
        for (size_t r = 0; r < m; r++)
            if (after[r].key == key) {
                if (memcmp(&after[r].S, &before[q].S, sizeof(double)) != 0)
                    fail_msg("pair %llx: slot %.17g after the rebuilds, %.17g before",
                             (unsigned long long)key, after[r].S, before[q].S);
                found++;
            }
    }
    assert_true(gone > 0);
    assert_int_equal(found + gone, n);
    assert_int_equal(m, found);
    free(keep);
    free(before);
    free(after);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

/* The run's state and the list's slots after `steps` more steps from a restore of snap (made
 * with coefficient k); wipe: the restored slots set to 0 first. */
static void resume(const cdem_snapshot *snap, double k, int steps, int wipe, cdem_state *s,
                   cdem_integrator *it) {
    cdem_error err;
    int boundary_forces = 0;
    assert_int_equal(cdem_state_init(s, 0, 0, &err), CDEM_OK);
    start(it, k);
    assert_int_equal(cdem_ckpt_state_get(s, snap, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_snapshot_get(it, snap, s, &boundary_forces, &err), CDEM_OK);
    if (wipe)
        memset(it->nb.slots, 0, it->nb.np * sizeof *it->nb.slots);
    run(it, s, steps);
}

static int same_run(const cdem_state *a, const cdem_integrator *ia, const cdem_state *b,
                    const cdem_integrator *ib) {
    const size_t n = a->n;
    return a->n == b->n && ia->nb.np == ib->nb.np && !memcmp(a->x, b->x, n * sizeof *a->x) &&
           !memcmp(a->y, b->y, n * sizeof *a->y) && !memcmp(a->vx, b->vx, n * sizeof *a->vx) &&
           !memcmp(a->vy, b->vy, n * sizeof *a->vy) &&
           !memcmp(ia->nb.slots, ib->nb.slots, ia->nb.np * sizeof *ia->nb.slots);
}

/* slip-4: a checkpoint holds the slots (nb.slot_count, nb.slots) and the coefficient (after the
 * values of contact.law); a run resumed from it is bit-identical to the one that went on, and
 * one whose restored slots are wiped is not (the slot carries the run). A resume with another
 * k is refused. */
static void test_law_test_slip_weakening_resume_bit_identical(void **state) {
    (void)state;
    cdem_state s, r;
    cdem_integrator it, ir;
    cdem_error err;
    make_pile(&s);
    start(&it, 0.75);
    run(&it, &s, 150);
    cdem_snapshot *snap = NULL;
    assert_int_equal(cdem_snapshot_alloc(&snap, &err), CDEM_OK);
    assert_int_equal(cdem_ckpt_state_put(&s, 0, snap, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_snapshot_put(&it, 0, snap, &err), CDEM_OK);
    const cdem_snapshot_array *slots = cdem_snapshot_get(snap, "nb.slots");
    assert_non_null(slots);
    assert_int_equal(slots->count, it.nb.np);
    const cdem_snapshot_array *law = cdem_snapshot_get(snap, "contact.law");
    assert_non_null(law);
    assert_true(((const double *)law->data)[law->count - 1] == 0.75);
    run(&it, &s, 150);

    resume(snap, 0.75, 150, 0, &r, &ir);
    assert_true(same_run(&s, &it, &r, &ir));
    cdem_integrator_free(&ir);
    cdem_state_free(&r);

    resume(snap, 0.75, 150, 1, &r, &ir);
    assert_false(same_run(&s, &it, &r, &ir));
    cdem_integrator_free(&ir);
    cdem_state_free(&r);

    int boundary_forces = 0;
    assert_int_equal(cdem_state_init(&r, 0, 0, &err), CDEM_OK);
    start(&ir, 0.5);
    assert_int_equal(cdem_ckpt_state_get(&r, snap, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_snapshot_get(&ir, snap, &r, &boundary_forces, &err),
                     CDEM_ERR_CONFLICT);
    assert_non_null(strstr(err.msg, "contact.law"));
    cdem_integrator_free(&ir);
    cdem_state_free(&r);

    cdem_snapshot_free(snap);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_law_test_slip_weakening_history_by_hand),
        cmocka_unit_test(test_law_test_slip_weakening_coefficient),
        cmocka_unit_test(test_law_test_slip_weakening_slot_survives_rebuild),
        cmocka_unit_test(test_law_test_slip_weakening_resume_bit_identical),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
