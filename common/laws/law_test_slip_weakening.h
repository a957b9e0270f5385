/* law_test_slip_weakening: a fixture of the tests, not a law of the model (no parameter file
 * can name it: its row is CDEM_TEST_LAW). It has one coefficient of its own, k =
 * material.test_slip_cohesion_share (a fixture's row: it parses and is recorded when set, but
 * is listed nowhere a user reads), and one history slot per contact, S, the slip the contact
 * has accumulated, as the spring force the slips cut off (N: Ks times the slip distance):
 *   Fs = Ks Xs,   |Fs| <= mu Fn + max(0, k C0 - S)   (C0 only while the contact is cohesive)
 *   at a slip     S += |Ks Xs| - limit
 * so a contact's cohesion is worn away by its own sliding. The proof that a law owns its
 * coefficients and its history (issue 45, item 2): this file, its line in laws.def and
 * tests/test_law_test_slip_weakening.c are all it took. Its parts: law.h. */
#if defined(CDEM_LAW_SCALAR) && !defined(CDEM_LAW_TEST_SLIP_WEAKENING_SCALAR)
#define CDEM_LAW_TEST_SLIP_WEAKENING_SCALAR

#include "law.h"

/* coef[0] = k; slots[0] = S, this contact's. */
static CDEM_INLINE cdem_shear cdem_law_test_slip_weakening(double spring, double fn, double mu,
                                                           double c0, const double *coef,
                                                           double *slots) {
    const double cohesion = coef[0] * c0 - slots[0];
    const double limit = mu * fn + (cohesion > 0.0 ? cohesion : 0.0);
    const cdem_shear sh = cdem_law_cap(spring, spring, limit);
    if (sh.slid)
        slots[0] += fabs(spring) - limit;
    return sh;
}

#endif

#if defined(CDEM_LAW_SETUP) && !defined(CDEM_LAW_TEST_SLIP_WEAKENING_SETUP)
#define CDEM_LAW_TEST_SLIP_WEAKENING_SETUP

/* k from its parameter (the table checks its range). */
static cdem_status cdem_law_test_slip_weakening_setup(const cdem_params *p, double *coef,
                                                      cdem_error *err) {
    (void)err;
    coef[0] = p->test_slip_cohesion_share;
    return CDEM_OK;
}

#endif

#ifdef CDEM_PARAM_FIELDS
double test_slip_cohesion_share; /* test-slip-weakening: k, the share of C0 before any slip */
#endif

/* clang-format off */
#ifdef CDEM_PARAM_ROWS
    {"material", "test_slip_cohesion_share", CDEM_PTYPE_DOUBLE, P_OFF(test_slip_cohesion_share), 0, "", "0.75", 0, 1, 0, 0, NULL,
     "test-slip-weakening (a fixture of the tests): the share k of C0 in the strength of a contact that has not slid", 1, 1},
#endif
/* clang-format on */

#ifdef CDEM_TEST_LAW
    CDEM_TEST_LAW(
        TEST_SLIP_WEAKENING, "test-slip-weakening",
        "tests only: shear strength mu Fn + max(0, k C0 - S), S the contact's accumulated "
        "slip (a history slot), k = test_slip_cohesion_share",
        cdem_law_test_slip_weakening, NULL)
#endif

#ifdef CDEM_LAW_STATE
        CDEM_LAW_STATE(TEST_SLIP_WEAKENING, 1, 1, cdem_law_test_slip_weakening_setup)
#endif
