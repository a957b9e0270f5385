/* law_normal_cohesion: C0 in parallel with the normal force, granular_law = normal-cohesion
 * (the default).
 *   Fs = Ks Xs,   |Fs| <= Fs_max = mu (Fn + C0)   (C0 only while the contact is cohesive)
 * The paper (Cardozo & Hardy 2023, Theory) and the manual describe the shear force as "a
 * threshold-limited elastic spring with a cohesive force term (C0) in parallel with that
 * used to calculate the normal force": the cohesion acts like an extra normal force pressing
 * the two elements together, so it raises the Coulomb threshold by mu C0. A frictionless
 * class (mu = 0: flexural slip, a frictionless weak interval, a smooth base) has no shear
 * strength at all, whatever its C0. Why this law is the default: docs/solver.md, "Which
 * law". The file's parts: law.h. */
#if defined(CDEM_LAW_SCALAR) && !defined(CDEM_LAW_NORMAL_COHESION_SCALAR)
#define CDEM_LAW_NORMAL_COHESION_SCALAR

#include "law.h"

static CDEM_INLINE cdem_shear cdem_law_normal_cohesion(double spring, double fn, double mu,
                                                       double c0) {
    return cdem_law_cap(spring, spring, mu * (fn + c0));
}

#endif

#if defined(CDEM_LAW_LANES) && !defined(CDEM_LAW_NORMAL_COHESION_LANES)
#define CDEM_LAW_NORMAL_COHESION_LANES

CDEM_LANES cdem_shear4 cdem_law_normal_cohesion_lanes(__m256d spring, __m256d fn, __m256d mu,
                                                      __m256d c0) {
    return cdem_law_cap4(spring, spring, _mm256_mul_pd(mu, _mm256_add_pd(fn, c0)));
}

#endif

#ifdef CDEM_LAW
CDEM_LAW(NORMAL_COHESION, "normal-cohesion", "shear strength mu (Fn + C0)",
         cdem_law_normal_cohesion, cdem_law_normal_cohesion_lanes)
#endif

#ifdef CDEM_LAW_STATE
CDEM_LAW_STATE(NORMAL_COHESION, 0, 0, NULL) /* no coefficients, no history slots */
#endif
