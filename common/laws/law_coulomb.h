/* law_coulomb: the Mohr-Coulomb granular contact, granular_law = coulomb.
 *   Fs = Ks Xs,   |Fs| <= Fs_max = mu Fn + C0   (C0 only while the contact is cohesive)
 * The cohesion adds to the strength, not to the spring force: an unloaded cohesive contact
 * carries no shear force, and at Fn = 0 it still resists C0 of shear, so with the paper's C0
 * cliffs many elements high stand (docs/solver.md, "Which law", has the numbers and the
 * law's history). Kept for users who want a Mohr-Coulomb contact. The file's parts:
 * law.h. */
#if defined(CDEM_LAW_SCALAR) && !defined(CDEM_LAW_COULOMB_SCALAR)
#define CDEM_LAW_COULOMB_SCALAR

#include "law.h"

static CDEM_INLINE cdem_shear cdem_law_coulomb(double spring, double fn, double mu, double c0) {
    double limit = mu * fn;
    if (c0 > 0.0)
        limit += c0;
    return cdem_law_cap(spring, spring, limit);
}

#endif

#if defined(CDEM_LAW_LANES) && !defined(CDEM_LAW_COULOMB_LANES)
#define CDEM_LAW_COULOMB_LANES

CDEM_LANES cdem_shear4 cdem_law_coulomb_lanes(__m256d spring, __m256d fn, __m256d mu, __m256d c0) {
    const __m256d l = _mm256_mul_pd(mu, fn);
    const __m256d limit = _mm256_blendv_pd(l, _mm256_add_pd(l, c0),
                                           _mm256_cmp_pd(c0, _mm256_setzero_pd(), _CMP_GT_OQ));
    return cdem_law_cap4(spring, spring, limit);
}

#endif

#ifdef CDEM_LAW
CDEM_LAW(COULOMB, "coulomb", "shear strength mu Fn + C0", cdem_law_coulomb, cdem_law_coulomb_lanes)
#endif

#ifdef CDEM_LAW_STATE
CDEM_LAW_STATE(COULOMB, 0, 0, NULL) /* no coefficients, no history slots */
#endif
