/* law_test_scalar_only: a fixture of the tests, not a law of the model (no parameter file can
 * name it: its row is CDEM_TEST_LAW). It has a scalar kernel and no AVX2 kernel, so the
 * vector path evaluates it pair by pair with the scalar one: tests/test_integrate.c's
 * comparison of the two paths, which loops over every registered law, keeps that fallback
 * checked, and its file and row are the whole of what a law needs (docs/architecture.md).
 *   Fs = Ks Xs,   |Fs| <= mu Fn + C0 / 2   (C0 only while the contact is cohesive)
 * The file's parts: law.h. */
#if defined(CDEM_LAW_SCALAR) && !defined(CDEM_LAW_TEST_SCALAR_ONLY_SCALAR)
#define CDEM_LAW_TEST_SCALAR_ONLY_SCALAR

#include "law.h"

static CDEM_INLINE cdem_shear cdem_law_test_scalar_only(double spring, double fn, double mu,
                                                        double c0) {
    return cdem_law_cap(spring, spring, mu * fn + 0.5 * c0);
}

#endif

#ifdef CDEM_TEST_LAW
CDEM_TEST_LAW(TEST_SCALAR_ONLY, "test-scalar-only", "tests only: shear strength mu Fn + C0 / 2",
              cdem_law_test_scalar_only, NULL)
#endif

#ifdef CDEM_LAW_STATE
CDEM_LAW_STATE(TEST_SCALAR_ONLY, 0, 0, NULL) /* no coefficients, no history slots */
#endif
