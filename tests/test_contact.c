/* Tests of solver/contact: the pair laws (the original manual and paper) against their closed
 * forms. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "contact.h"
#include "integrate.h"
#include "state.h"

#include <math.h>
#include <string.h>

#define KN 1.0e9
#define KS 5.0e8

static cdem_params base_params(cdem_material_model model) {
    cdem_params p;
    memset(&p, 0, sizeof p);
    p.material = model;
    p.first_slip = 1;
    p.granular_law = CDEM_LAW_COULOMB;
    p.cohesive_contacts = CDEM_COHESIVE_EQUILIBRATED;
    p.settling_friction = 1.0;
    p.element =
        (cdem_contact_material){.friction = 0.25, .cohesion = 5.0e6, .breaking_strain = 0.02};
    p.wall = (cdem_contact_material){.friction = 0.5, .cohesion = 1.0e6, .breaking_strain = 0.05};
    p.fault = (cdem_contact_material){.friction = 0.0, .cohesion = 0.0, .breaking_strain = 0.01};
    p.base = (cdem_contact_material){.friction = NAN, .cohesion = NAN, .breaking_strain = NAN};
    return p;
}

static cdem_contact_law make_law_of(cdem_material_model model, int first_slip,
                                    cdem_granular_law granular) {
    cdem_params p = base_params(model);
    p.first_slip = first_slip;
    p.granular_law = granular;
    cdem_contact_law law;
    cdem_error err;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_OK);
    return law;
}

/* The Mohr-Coulomb law (granular_law = coulomb), whose hand-computed cases follow. */
static cdem_contact_law make_law(cdem_material_model model, int first_slip) {
    return make_law_of(model, first_slip, CDEM_LAW_COULOMB);
}

static void test_contact_normal_repulsion(void **st) {
    (void)st;
    cdem_contact_law law = make_law(CDEM_MATERIAL_GRANULAR, 1);
    const double R = 200.0, delta = 1.5;
    double xs = 0.0, fx = 0, fy = 0;
    uint8_t h = 0;
    /* j to the right of i, overlapping by delta: i is pushed to -x with Kn delta */
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R - delta, 0.0, R, 0, 0, 0.1, &xs, &h, NULL, &fx,
                      &fy);
    assert_float_equal(fx, -KN * delta, 1e-6 * KN * delta);
    assert_float_equal(fy, 0.0, 1e-9);
    assert_true(h & CDEM_PAIR_TOUCH);
    /* same along a diagonal: magnitude Kn delta along -n */
    const double c = cos(0.3), s = sin(0.3);
    h = 0;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, (R - delta) * c, (R - delta) * s, R, 0, 0, 0.1, &xs,
                      &h, NULL, &fx, &fy);
    assert_float_equal(fx, -KN * delta * c, 1e-6 * KN * delta);
    assert_float_equal(fy, -KN * delta * s, 1e-6 * KN * delta);
    /* separated: no force, no history */
    xs = 3.0;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R + 0.1, 0.0, R, 0, 0, 0.1, &xs, &h, NULL, &fx,
                      &fy);
    assert_true(fx == 0.0 && fy == 0.0 && xs == 0.0 && h == 0);
}

static void test_contact_bond_attraction_breaking(void **st) {
    (void)st;
    cdem_contact_law law = make_law(CDEM_MATERIAL_BONDED, 1);
    const double R = 200.0, r0 = 0.02; /* element breaking strain */
    double xs = 0.0, fx = 0, fy = 0;
    uint8_t h = CDEM_PAIR_BONDED;
    /* stretched by half the breaking distance: attraction Kn (r - R) toward j (+x) */
    double stretch = 0.5 * r0 * R;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R + stretch, 0, R, 0, 0, 0.1, &xs, &h, NULL, &fx,
                      &fy);
    assert_float_equal(fx, KN * stretch, 1e-6 * KN * stretch);
    assert_true(h & CDEM_PAIR_BONDED);
    /* just below the threshold: still intact */
    stretch = 0.999 * r0 * R;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R + stretch, 0, R, 0, 0, 0.1, &xs, &h, NULL, &fx,
                      &fy);
    assert_true(h & CDEM_PAIR_BONDED);
    assert_float_equal(fx, KN * stretch, 1e-6 * KN * stretch);
    /* at r - R = r0 R: breaks for good, force zero */
    stretch = r0 * R * 1.0001;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R + stretch, 0, R, 0, 0, 0.1, &xs, &h, NULL, &fx,
                      &fy);
    assert_false(h & CDEM_PAIR_BONDED);
    assert_true(fx == 0.0 && fy == 0.0);
    /* back to a small stretch: no attraction any more */
    stretch = 0.1 * r0 * R;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R + stretch, 0, R, 0, 0, 0.1, &xs, &h, NULL, &fx,
                      &fy);
    assert_true(fx == 0.0 && fy == 0.0);
    /* compression: still repulsive */
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R - 2.0, 0, R, 0, 0, 0.1, &xs, &h, NULL, &fx, &fy);
    assert_float_equal(fx, -KN * 2.0, 1e-3);
    /* bonded model has no tangential force */
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R - 2.0, 0, R, 0, 100.0, 0.1, &xs, &h, NULL, &fx,
                      &fy);
    assert_true(fy == 0.0);
    /* wall class uses the wall breaking strain (0.05): a stretch of 0.03 R holds there */
    h = CDEM_PAIR_BONDED;
    cdem_contact_eval(&law, CDEM_CLASS_WALL, R * 1.03, 0, R, 0, 0, 0.1, &xs, &h, NULL, &fx, &fy);
    assert_true(h & CDEM_PAIR_BONDED);
    h = CDEM_PAIR_BONDED;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R * 1.03, 0, R, 0, 0, 0.1, &xs, &h, NULL, &fx, &fy);
    assert_false(h & CDEM_PAIR_BONDED);
}

/* Drives a tangential displacement on a pair (j at +x, tangent +y) in steps of dxs, returns
 * the shear force on i (along +y) after each step in out[]. */
static void drive(const cdem_contact_law *law, int cls, double R, double delta, double dxs,
                  int nsteps, double *xs, uint8_t *h, double *out) {
    const double dt = 0.01;
    for (int k = 0; k < nsteps; k++) {
        double fx, fy;
        cdem_contact_eval(law, cls, R - delta, 0.0, R, 0.0, dxs / dt, dt, xs, h, NULL, &fx, &fy);
        out[k] = fy;
    }
}

static void test_contact_coulomb_limit_first_slip(void **st) {
    (void)st;
    cdem_contact_law law = make_law(CDEM_MATERIAL_GRANULAR, 1);
    const double R = 200.0, delta = 0.5, fn = KN * delta;
    const double mu = 0.25, c0 = 5.0e6, limit = mu * fn + c0; /* 1.25e8 + 5e6 */
    double xs = 0.0, f[200];
    uint8_t h = CDEM_PAIR_COHESIVE;
    const double dxs = 0.011; /* Ks * dxs = 5.5e6 N per step: the limit falls mid-step */
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, dxs, 200, &xs, &h, f);
    /* below the limit: Fs = Ks Xs */
    for (int k = 0; k < 20; k++)
        assert_float_equal(f[k], KS * dxs * (k + 1), 1e-6 * KS * dxs * (k + 1));
    /* the first step beyond the limit is scaled back to mu Fn + C0 exactly */
    int kslip = (int)floor(limit / (KS * dxs)); /* 23 steps stay below */
    assert_float_equal(f[kslip - 1], KS * dxs * kslip, 1.0);
    assert_float_equal(f[kslip], limit, 1e-6 * limit);
    /* then cohesion is gone: mu Fn */
    assert_float_equal(f[kslip + 1], mu * fn, 1e-6 * fn);
    assert_float_equal(f[199], mu * fn, 1e-6 * fn);
    assert_false(h & CDEM_PAIR_COHESIVE);
    assert_float_equal(xs, mu * fn / KS, 1e-9);
    /* reversing the drive unloads elastically from the limit */
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, -dxs, 1, &xs, &h, f);
    assert_float_equal(f[0], mu * fn - KS * dxs, 1e-6 * fn);
}

static void test_contact_cohesion_lost_at_separation(void **st) {
    (void)st;
    cdem_contact_law law = make_law(CDEM_MATERIAL_GRANULAR, 0);
    const double R = 200.0, delta = 0.5, fn = KN * delta;
    const double limit = 0.25 * fn + 5.0e6;
    double xs = 0.0, f[200];
    uint8_t h = CDEM_PAIR_COHESIVE;
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, 0.01, 200, &xs, &h, f);
    /* first_slip off: it keeps sliding at mu Fn + C0 */
    assert_float_equal(f[199], limit, 1e-6 * limit);
    assert_true(h & CDEM_PAIR_COHESIVE);
    /* separation deletes the history and cohesion */
    double fx, fy;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R + 1.0, 0, R, 0, 0, 0.01, &xs, &h, NULL, &fx, &fy);
    assert_true(h == 0 && xs == 0.0 && fx == 0.0 && fy == 0.0);
    /* a new contact is not cohesive: limit mu Fn */
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, 0.01, 200, &xs, &h, f);
    assert_float_equal(f[199], 0.25 * fn, 1e-6 * fn);
}

/* granular_law = normal-cohesion (C0 in parallel with the normal force): a cohesive contact
 * sticks up to mu (Fn + C0), slides there on its first slip, then (first slip on) holds
 * mu Fn; a frictionless class has no shear strength whatever its C0. */
static void test_contact_normal_cohesion_limit_first_slip(void **st) {
    (void)st;
    cdem_contact_law law = make_law_of(CDEM_MATERIAL_GRANULAR, 1, CDEM_LAW_NORMAL_COHESION);
    const double R = 200.0, delta = 0.5, fn = KN * delta;
    const double mu = 0.25, c0 = 5.0e6, limit = mu * (fn + c0); /* 1.25e8 + 1.25e6 */
    double xs = 0.0, f[200];
    uint8_t h = CDEM_PAIR_COHESIVE;
    const double dxs = 0.011; /* 5.5e6 N per step */
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, dxs, 200, &xs, &h, f);
    const int kslip = (int)floor(limit / (KS * dxs)); /* 22 steps stay below */
    assert_int_equal(kslip, 22);
    for (int k = 0; k < kslip; k++)
        assert_float_equal(f[k], KS * dxs * (k + 1), 1e-6 * KS * dxs * (k + 1));
    assert_float_equal(f[kslip], limit, 1e-9 * limit);
    assert_float_equal(f[kslip + 1], mu * fn, 1e-9 * fn);
    assert_false(h & CDEM_PAIR_COHESIVE);
    assert_float_equal(xs, mu * fn / KS, 1e-12);
    /* first slip off: it keeps sliding at mu (Fn + C0) until the pair separates */
    law = make_law_of(CDEM_MATERIAL_GRANULAR, 0, CDEM_LAW_NORMAL_COHESION);
    xs = 0.0;
    h = CDEM_PAIR_COHESIVE;
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, dxs, 200, &xs, &h, f);
    assert_float_equal(f[199], limit, 1e-9 * limit);
    assert_true(h & CDEM_PAIR_COHESIVE);
    /* ... and loses its cohesion when the pair separates: a new contact holds mu Fn */
    double fx, fy;
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R + 1.0, 0, R, 0, 0, 0.01, &xs, &h, NULL, &fx, &fy);
    assert_true(h == 0 && xs == 0.0 && fx == 0.0 && fy == 0.0);
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, dxs, 200, &xs, &h, f);
    assert_float_equal(f[199], mu * fn, 1e-9 * fn);
    /* at Fn -> 0 the strength is mu C0 (a 1 um overlap: Fn = 1e3 N) */
    xs = 0.0;
    h = CDEM_PAIR_COHESIVE;
    drive(&law, CDEM_CLASS_ELEMENT, R, 1e-6, 1.0, 1, &xs, &h, f);
    assert_float_equal(f[0], mu * (KN * 1e-6 + c0), 1e-6 * mu * c0);
    /* a frictionless cohesive class (the fault class here: mu 0, C0 0) and a frictionless
     * class with cohesion have no shear strength */
    cdem_params p = base_params(CDEM_MATERIAL_GRANULAR);
    p.granular_law = CDEM_LAW_NORMAL_COHESION;
    p.fault.cohesion = 1e9;
    cdem_error err;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_OK);
    xs = 0.0;
    h = CDEM_PAIR_COHESIVE;
    drive(&law, CDEM_CLASS_FAULT, R, delta, dxs, 3, &xs, &h, f);
    assert_float_equal(f[2], 0.0, 0.0);
}

/* granular_law = spring-cohesion (the manual's Eq. 2 as printed): Fs = Ks Xs + C0 sgn(Xs)
 * below mu Fn, capped at mu Fn; the stored spring then holds the limit force. */
static void test_contact_spring_cohesion(void **st) {
    (void)st;
    cdem_contact_law law = make_law_of(CDEM_MATERIAL_GRANULAR, 0, CDEM_LAW_SPRING_COHESION);
    const double R = 200.0, delta = 0.5, fn = KN * delta, mu = 0.25, c0 = 5.0e6;
    double xs = 0.0, f[40];
    uint8_t h = CDEM_PAIR_COHESIVE;
    const double dxs = 0.011;
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, dxs, 40, &xs, &h, f);
    /* (mu Fn - C0) / (Ks dxs) = 21.8: 21 steps below the cap */
    for (int k = 0; k < 21; k++)
        assert_float_equal(f[k], KS * dxs * (k + 1) + c0, 1e-9 * mu * fn);
    assert_float_equal(f[21], mu * fn, 1e-9 * fn);
    assert_float_equal(f[39], mu * fn, 1e-9 * fn);
    assert_float_equal(xs, mu * fn / KS, 1e-12);
    assert_true(h & CDEM_PAIR_COHESIVE); /* first slip off: kept */
    /* the cohesive term follows the sense of the tangential displacement */
    xs = 0.0;
    h = CDEM_PAIR_COHESIVE;
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, -dxs, 1, &xs, &h, f);
    assert_float_equal(f[0], -KS * dxs - c0, 1e-9 * c0);
    /* a non-cohesive contact is plain Coulomb */
    xs = 0.0;
    h = 0;
    drive(&law, CDEM_CLASS_ELEMENT, R, delta, dxs, 1, &xs, &h, f);
    assert_float_equal(f[0], KS * dxs, 1e-9 * c0);
}

/* The law in force on a step (cdem_contact_law_phase): while equilibrating, friction x
 * settling_friction and no forming contact is cohesive; afterwards the material, and with
 * cohesive_contacts = formed a contact that forms (or re-forms after a separation) is
 * cohesive until its first slip. */
static void test_contact_phases_settling_friction_and_formed_contacts(void **st) {
    (void)st;
    cdem_params p = base_params(CDEM_MATERIAL_GRANULAR);
    p.granular_law = CDEM_LAW_NORMAL_COHESION;
    p.cohesive_contacts = CDEM_COHESIVE_FORMED;
    p.settling_friction = 0.4;
    cdem_contact_law law, now;
    cdem_error err;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_OK);
    const double R = 200.0, delta = 0.5, fn = KN * delta, c0 = 5.0e6;
    double xs = 0.0, f[1];
    uint8_t h = 0;
    /* equilibrating: a new contact pushed past its strength slides at 0.4 mu Fn */
    cdem_contact_law_phase(&law, 1, &now);
    assert_float_equal(now.friction[CDEM_CLASS_WALL], 0.4 * 0.5, 1e-15);
    assert_false(now.cohesive_new);
    drive(&now, CDEM_CLASS_ELEMENT, R, delta, 10.0, 1, &xs, &h, f);
    assert_float_equal(f[0], 0.4 * 0.25 * fn, 1e-9 * fn);
    assert_true(h == CDEM_PAIR_TOUCH);
    /* deforming: the same touching contact stays non-cohesive (it did not form now) */
    cdem_contact_law_phase(&law, 0, &now);
    assert_float_equal(now.friction[CDEM_CLASS_ELEMENT], 0.25, 0.0);
    assert_true(now.cohesive_new);
    drive(&now, CDEM_CLASS_ELEMENT, R, delta, 10.0, 1, &xs, &h, f);
    assert_float_equal(f[0], 0.25 * fn, 1e-9 * fn);
    /* separated, then touching again: a formed contact, cohesive */
    double fx, fy;
    cdem_contact_eval(&now, CDEM_CLASS_ELEMENT, R + 1.0, 0, R, 0, 0, 0.01, &xs, &h, NULL, &fx, &fy);
    assert_int_equal(h, 0);
    drive(&now, CDEM_CLASS_ELEMENT, R, delta, 0.0, 1, &xs, &h, f);
    assert_true(h & CDEM_PAIR_COHESIVE);
    drive(&now, CDEM_CLASS_ELEMENT, R, delta, 10.0, 1, &xs, &h, f);
    assert_float_equal(f[0], 0.25 * (fn + c0), 1e-9 * fn); /* its first slip */
    assert_false(h & CDEM_PAIR_COHESIVE);                  /* first slip on: lost */
    /* equilibrated (the default): forming contacts are never cohesive */
    p.cohesive_contacts = CDEM_COHESIVE_EQUILIBRATED;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_OK);
    cdem_contact_law_phase(&law, 0, &now);
    assert_false(now.cohesive_new);
    h = 0;
    xs = 0.0;
    drive(&now, CDEM_CLASS_ELEMENT, R, delta, 0.0, 1, &xs, &h, f);
    assert_int_equal(h, CDEM_PAIR_TOUCH);
    /* the bonded model never makes a forming contact bonded */
    p.material = CDEM_MATERIAL_BONDED;
    p.cohesive_contacts = CDEM_COHESIVE_FORMED;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_OK);
    cdem_contact_law_phase(&law, 0, &now);
    h = 0;
    drive(&now, CDEM_CLASS_ELEMENT, R, delta, 0.0, 1, &xs, &h, f);
    assert_false(h & CDEM_PAIR_BONDED);
}

/* cohesive_contacts = initial: a contact of the built assembly keeps its mark while it touches
 * or stays within round-off of a tangency, loses it when the pair separates, and at the end of
 * equilibration only the still-marked touching pairs become cohesive. */
static void test_contact_initial_contacts(void **st) {
    (void)st;
    cdem_contact_law law = make_law(CDEM_MATERIAL_GRANULAR, 1);
    const double R = 200.0;
    double xs = 0.0, fx, fy;
    uint8_t h = CDEM_PAIR_INITIAL;
    /* an exact tangency up to round-off: no force, the mark kept */
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R * (1.0 + 1e-12), 0, R, 0, 0, 0.01, &xs, &h, NULL,
                      &fx, &fy);
    assert_int_equal(h, CDEM_PAIR_INITIAL);
    assert_true(fx == 0.0 && fy == 0.0);
    /* touching: the mark rides along with the touch flag */
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R - 0.5, 0, R, 0, 0, 0.01, &xs, &h, NULL, &fx, &fy);
    assert_int_equal(h, CDEM_PAIR_INITIAL | CDEM_PAIR_TOUCH);
    /* separated (1 mm beyond the tangency): the mark is gone for good */
    cdem_contact_eval(&law, CDEM_CLASS_ELEMENT, R + 1e-3, 0, R, 0, 0, 0.01, &xs, &h, NULL, &fx,
                      &fy);
    assert_int_equal(h, 0);
    assert_int_equal(cdem_contact_separated(CDEM_PAIR_INITIAL | CDEM_PAIR_COHESIVE, R * R, R),
                     CDEM_PAIR_INITIAL);
    assert_int_equal(cdem_contact_separated(CDEM_PAIR_COHESIVE, R * R, R), 0);

    /* through the integrator: three elements in a row, a-b tangent (built contact), b-c
     * overlapping by 1 m but marked after the build is moved apart */
    cdem_params p = base_params(CDEM_MATERIAL_GRANULAR);
    p.granular_law = CDEM_LAW_NORMAL_COHESION;
    p.cohesive_contacts = CDEM_COHESIVE_INITIAL;
    cdem_model m;
    memset(&m, 0, sizeof m);
    const double r[4] = {50.0, 75.0, 100.0, 125.0};
    for (int k = 0; k < 4; k++) {
        m.radius[k] = r[k];
        m.mass[k] = 2500.0 * M_PI * r[k] * r[k];
    }
    m.min_mass = m.mass[0];
    m.max_radius = 125.0;
    m.kn = KN;
    m.ks = KS;
    m.dt = 0.01;
    cdem_error err;
    cdem_state s;
    cdem_integrator it;
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 0.0, 0.0, 100.0, m.mass[2], 1, 0u, 0, NULL, &err),
                     CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 200.0, 0.0, 100.0, m.mass[2], 1, 0u, 0, NULL, &err),
                     CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 399.0, 0.0, 100.0, m.mass[2], 1, 0u, 0, NULL, &err),
                     CDEM_OK);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_mark_initial(&it, &s), 2);
    /* c moves away from b (beyond reach), then back into contact */
    s.x[2] = 402.0;
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    s.x[2] = 399.0;
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    /* a and b: pushed into contact; only that pair becomes cohesive */
    s.x[1] = 199.5;
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_make_cohesive(&it, &s), 1);
    long contacts = 0, cohesive = 0;
    cdem_integrator_count(&it, &contacts, &cohesive);
    assert_int_equal(contacts, 2);
    assert_int_equal(cohesive, 1);
    for (size_t k = 0; k < it.nb.np; k++) /* the marks have served */
        assert_false(it.nb.hist[k] & CDEM_PAIR_INITIAL);
    /* the other rules mark nothing */
    cdem_integrator_free(&it);
    p.cohesive_contacts = CDEM_COHESIVE_EQUILIBRATED;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_mark_initial(&it, &s), 0);
    assert_int_equal(cdem_integrator_make_cohesive(&it, &s), 2);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

static void test_contact_wall_and_fault_materials(void **st) {
    (void)st;
    cdem_contact_law law = make_law(CDEM_MATERIAL_GRANULAR, 0);
    const double R = 200.0, delta = 0.5, fn = KN * delta;
    double xs = 0.0, f[300];
    uint8_t h = CDEM_PAIR_COHESIVE;
    int cls = cdem_contact_class(0, CDEM_FLAG_WALL);
    assert_int_equal(cls, CDEM_CLASS_WALL);
    drive(&law, cls, R, delta, 0.01, 300, &xs, &h, f);
    assert_float_equal(f[299], 0.5 * fn + 1.0e6, 1e-6 * fn); /* wall: mu 0.5, C0 1e6 */
    cls = cdem_contact_class(CDEM_FLAG_FAULT, 0);
    assert_int_equal(cls, CDEM_CLASS_FAULT);
    xs = 0.0;
    h = CDEM_PAIR_COHESIVE;
    drive(&law, cls, R, delta, 0.01, 10, &xs, &h, f);
    assert_float_equal(f[9], 0.0, 1e-9); /* frictionless, cohesionless fault */
    /* boundary-boundary pairs and display footwall elements never interact */
    assert_int_equal(cdem_contact_class(CDEM_FLAG_WALL, CDEM_FLAG_WALL | CDEM_FLAG_MOVING), -1);
    assert_int_equal(cdem_contact_class(CDEM_FLAG_WALL, CDEM_FLAG_FAULT), -1);
    assert_int_equal(cdem_contact_class(0, CDEM_FLAG_FOOTWALL), -1);
    assert_int_equal(cdem_contact_class(CDEM_FLAG_WEAK, CDEM_FLAG_GROWTH), CDEM_CLASS_ELEMENT);
    assert_string_equal(cdem_contact_class_name(CDEM_CLASS_FAULT), "fault");
}

/* The base (wall elements flagged CDEM_FLAG_BASE) has its own class: it takes the wall's
 * values where its own are NaN (parameter word "wall", the default), else its own. */
static void test_contact_base_material(void **st) {
    (void)st;
    assert_int_equal(cdem_contact_class(0, CDEM_FLAG_WALL | CDEM_FLAG_BASE), CDEM_CLASS_BASE);
    assert_int_equal(cdem_contact_class(CDEM_FLAG_WALL | CDEM_FLAG_BASE, CDEM_FLAG_WEAK),
                     CDEM_CLASS_BASE);
    assert_int_equal(cdem_contact_class(0, CDEM_FLAG_WALL), CDEM_CLASS_WALL);
    assert_string_equal(cdem_contact_class_name(CDEM_CLASS_BASE), "base");
    cdem_params p = base_params(CDEM_MATERIAL_GRANULAR);
    cdem_contact_law law;
    cdem_error err;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_OK);
    assert_float_equal(law.friction[CDEM_CLASS_BASE], 0.5, 0.0); /* the wall's */
    assert_float_equal(law.cohesion[CDEM_CLASS_BASE], 1.0e6, 0.0);
    p.base.friction = 0.0; /* a smooth detachment under frictional lateral walls */
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_OK);
    assert_float_equal(law.friction[CDEM_CLASS_BASE], 0.0, 0.0);
    assert_float_equal(law.cohesion[CDEM_CLASS_BASE], 1.0e6, 0.0); /* still the wall's */
    assert_float_equal(law.friction[CDEM_CLASS_WALL], 0.5, 0.0);
    /* a sheared cohesive element-base contact: no strength with mu = 0 (coulomb: C0 only) */
    const double R = 200.0, delta = 0.5;
    double xs = 0.0, f[3];
    uint8_t h = CDEM_PAIR_COHESIVE;
    drive(&law, CDEM_CLASS_BASE, R, delta, 10.0, 1, &xs, &h, f);
    assert_float_equal(f[0], 1.0e6, 1e-6); /* the limit mu Fn + C0 = C0 */
    p.base.friction = -1.0;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "material.base_friction"));
}

static void test_contact_law_rejects_bad_values(void **st) {
    (void)st;
    cdem_params p = base_params(CDEM_MATERIAL_GRANULAR);
    cdem_contact_law law;
    cdem_error err;
    p.wall.friction = -0.1;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "material.wall_friction"));
    assert_non_null(strstr(err.msg, "-0.1"));
    p = base_params(CDEM_MATERIAL_BONDED);
    p.fault.breaking_strain = 0.0;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "material.fault_breaking_strain"));
    p = base_params(CDEM_MATERIAL_GRANULAR);
    assert_int_equal(cdem_contact_law_init(&law, &p, 0.0, KS, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "model.kn = 0"));
    p = base_params(CDEM_MATERIAL_GRANULAR);
    p.settling_friction = 1.5;
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "material.settling_friction = 1.5"));
    p = base_params(CDEM_MATERIAL_BONDED);
    assert_int_equal(cdem_contact_law_init(&law, &p, KN, KS, &err), CDEM_OK);
    assert_float_equal(law.max_breaking_strain, 0.05, 1e-15);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contact_normal_repulsion),
        cmocka_unit_test(test_contact_bond_attraction_breaking),
        cmocka_unit_test(test_contact_coulomb_limit_first_slip),
        cmocka_unit_test(test_contact_cohesion_lost_at_separation),
        cmocka_unit_test(test_contact_normal_cohesion_limit_first_slip),
        cmocka_unit_test(test_contact_spring_cohesion),
        cmocka_unit_test(test_contact_phases_settling_friction_and_formed_contacts),
        cmocka_unit_test(test_contact_initial_contacts),
        cmocka_unit_test(test_contact_wall_and_fault_materials),
        cmocka_unit_test(test_contact_base_material),
        cmocka_unit_test(test_contact_law_rejects_bad_values),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
