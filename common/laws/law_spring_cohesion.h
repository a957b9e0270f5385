/* law_spring_cohesion: the manual's Equation 2 as printed, granular_law = spring-cohesion.
 *   Fs = Ks Xs + C0 sgn(Xs),   |Fs| <= Fs_max = mu Fn   (C0 only while cohesive)
 * The cohesion is added to the elastic shear force in the sense of the tangential
 * displacement, and the Coulomb cap mu Fn has no cohesive part: a cohesive contact pushes
 * its pair apart tangentially with C0 as soon as it is sheared at all, and is at its limit
 * whenever C0 > mu Fn. With the paper's values the whole assembly flows (docs/solver.md,
 * "Which law"); kept so that the printed equation can be run and compared. At the limit the
 * spring is set so that Ks Xs alone equals the limit force (the spring stores the force,
 * cohesion excluded). The file's parts: law.h. */
#if defined(CDEM_LAW_SCALAR) && !defined(CDEM_LAW_SPRING_COHESION_SCALAR)
#define CDEM_LAW_SPRING_COHESION_SCALAR

#include "law.h"

static CDEM_INLINE cdem_shear cdem_law_spring_cohesion(double spring, double fn, double mu,
                                                       double c0) {
    double f = spring;
    if (c0 > 0.0 && spring != 0.0)
        f += spring > 0.0 ? c0 : -c0;
    return cdem_law_cap(f, spring, mu * fn);
}

#endif

#if defined(CDEM_LAW_LANES) && !defined(CDEM_LAW_SPRING_COHESION_LANES)
#define CDEM_LAW_SPRING_COHESION_LANES

CDEM_LANES cdem_shear4 cdem_law_spring_cohesion_lanes(__m256d spring, __m256d fn, __m256d mu,
                                                      __m256d c0) {
    const __m256d zero = _mm256_setzero_pd(), sign = _mm256_set1_pd(-0.0);
    const __m256d add = _mm256_and_pd(_mm256_cmp_pd(c0, zero, _CMP_GT_OQ),
                                      _mm256_cmp_pd(spring, zero, _CMP_NEQ_UQ));
    const __m256d sc =
        _mm256_blendv_pd(_mm256_xor_pd(c0, sign), c0, _mm256_cmp_pd(spring, zero, _CMP_GT_OQ));
    const __m256d f = _mm256_blendv_pd(spring, _mm256_add_pd(spring, sc), add);
    return cdem_law_cap4(f, spring, _mm256_mul_pd(mu, fn));
}

#endif

#ifdef CDEM_LAW
CDEM_LAW(SPRING_COHESION, "spring-cohesion", "Fs = Ks Xs + C0, shear strength mu Fn",
         cdem_law_spring_cohesion, cdem_law_spring_cohesion_lanes)
#endif

#ifdef CDEM_LAW_STATE
CDEM_LAW_STATE(SPRING_COHESION, 0, 0, NULL) /* no coefficients, no history slots */
#endif
