/* law_fixtures: a contact pushed far past its strength, for the tests of the granular laws
 * (test_registry_solver.c, test_law_test_scalar_only.c): two elements overlapping by 1 mm
 * (Kn = Ks = 1e9 N/m, so Fn = 1e6 N to the rounding of the distance), mu 0.25, a cohesive
 * contact of C0 = 5e8 N, and 1000 m of tangential spring. The tangential force it transmits
 * is the law's limit. Header-only, static: each test includes what it uses. */
#ifndef CDEM_TEST_LAW_FIXTURES_H
#define CDEM_TEST_LAW_FIXTURES_H

#include "contact.h"
#include "params.h"

#include <stdint.h>

#define LAW_FX_MU 0.25
#define LAW_FX_C0 5e8
#define LAW_FX_FN (1e9 * (2.0 - 1.999)) /* N, up to the rounding of the distance */

/* The tangential force (N, along t = (0, 1)) of the sliding contact under law `law`. */
__attribute__((unused)) static double law_fx_sliding_force(cdem_granular_law law) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.granular_law = law;
    p.element.friction = LAW_FX_MU;
    p.element.cohesion = LAW_FX_C0;
    cdem_contact_law cl;
    cdem_error err;
    if (cdem_contact_law_init(&cl, &p, 1e9, 1e9, &err) != CDEM_OK)
        fail_msg("material.granular_law = %s is refused: %s", cdem_law_name(law), err.msg);
    assert_int_equal(cl.granular, (int)law);
    /* i at the origin, j at (1.999, 0): R - r = 1e-3 m; t = (0, 1) */
    const double dx = 1.999, R = 2.0;
    double xs = 1000.0, fx = 0.0, fy = 0.0;
    uint8_t hist = CDEM_PAIR_TOUCH | CDEM_PAIR_COHESIVE;
    double slots[16] = {0.0}; /* the law's history slots, a contact that has none yet */
    assert_true(cl.slot_count <= 16);
    cdem_contact_touching(&cl, CDEM_CLASS_ELEMENT, dx * dx, dx, 0.0, R, 0.0, 0.0, 0.01, &xs, &hist,
                          slots, &fx, &fy);
    return fy;
}

#endif
