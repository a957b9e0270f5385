/* force_avx2: the AVX2 evaluation of a block of pairs (force_pairs.h), four pairs per step in
 * the lanes of 256-bit registers: the gathers of the two elements' positions and velocities,
 * the distance, the touch test, the square root and the division, the normal and the trial
 * tangential force, and the granular law's AVX2 kernel (common/laws/law_*.h: masks (blends)
 * where its scalar kernel branches); the history bytes per lane. Each law has a loop of its
 * own, its kernel inlined, chosen by one switch generated from laws.def; a law without an
 * AVX2 kernel is evaluated pair by pair by its scalar kernel, never by another law's. A group
 * of four falls back to the scalar kernel when one of its pairs is an intact bond (bonded
 * model) or belongs to another chunk; so does the tail of the block. Compiled for the baseline
 * x86-64 like the rest, with target("avx2") on these functions only, so the scalar path still runs
 * on any x86-64; elsewhere this file provides cdem_force_avx2_usable() = 0 and the scalar path is
 * the only one. */
#include "force_pairs.h"

#include <string.h>

#if defined(__GNUC__) && defined(__x86_64__)

#include <immintrin.h>

#define AVX2 __attribute__((target("avx2")))

/* the laws' AVX2 kernels (common/laws/law.h) */
#define CDEM_LAW_LANES
#include "laws/law.h"
#include "laws/laws.def"

int cdem_force_avx2_usable(void) {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") ? 1 : 0;
}

/* The lanes of a vector, lowest first. */
AVX2 static inline void lanes(__m256d v, double out[4]) {
    _mm256_storeu_pd(out, v);
}

/* pj[p] - pi[p] differences of one array for the four pairs. */
AVX2 static inline __m256d gather_diff(const double *v, __m128i i4, __m128i j4) {
    return _mm256_sub_pd(_mm256_i32gather_pd(v, j4, 8), _mm256_i32gather_pd(v, i4, 8));
}

/* The four pairs at p by the scalar kernel (those whose pj is below `below`). */
AVX2 static long group_scalar(const cdem_force_pairs *a, long p, long end, int32_t below) {
    long left = 0;
    for (long q = p; q < end; q++) {
        if (a->pj[q] < below)
            cdem_force_pair_at(a, q);
        else
            left++;
    }
    return left;
}

/* The separated lanes (mask) with a history: what cdem_force_pair does for them (the force
 * slots are written by the caller). */
AVX2 static void separated_lanes(const cdem_force_pairs *a, long p, const uint8_t hb[4], __m256d r2,
                                 __m256d R, int mask) {
    double r2l[4], Rl[4];
    lanes(r2, r2l);
    lanes(R, Rl);
    for (int k = 0; k < 4; k++)
        if (((mask >> k) & 1) && hb[k]) {
            a->hist[p + k] = cdem_contact_separated(hb[k], r2l[k], Rl[k]);
            a->xs[p + k] = 0.0;
        }
}

/* A byte mask per bit of a 4-bit lane mask: byte k of lane_bytes[m] is 0xff when bit k of m
 * is set (the history bytes of four pairs handled as one 32-bit word). */
static const uint32_t lane_bytes[16] = {0x00000000u, 0x000000ffu, 0x0000ff00u, 0x0000ffffu,
                                        0x00ff0000u, 0x00ff00ffu, 0x00ffff00u, 0x00ffffffu,
                                        0xff000000u, 0xff0000ffu, 0xff00ff00u, 0xff00ffffu,
                                        0xffff0000u, 0xffff00ffu, 0xffffff00u, 0xffffffffu};

/* The AVX2 kernel of a law (law.h): four contacts' trial spring force, normal force,
 * friction and cohesion in, the transmitted force, the spring kept and the slip mask out. */
typedef cdem_shear4 (*law_lanes)(__m256d spring, __m256d fn, __m256d mu, __m256d c0);

/* cdem_force_pairs_avx2 for the law whose AVX2 kernel is `lanes` (a constant at each call,
 * so the kernel is inlined and each law has a loop of its own). */
AVX2 static inline __attribute__((always_inline)) long
pairs_with_law(const cdem_force_pairs *a, long p0, long p1, int32_t below, law_lanes lanes) {
    const cdem_contact_law *law = a->law;
    const int tangential = law->model == CDEM_MATERIAL_GRANULAR && law->ks > 0.0;
    /* the history rules on four bytes at once: every byte's TOUCH bit set, COHESIVE added to
     * the bytes that were not touching when forming contacts are cohesive, COHESIVE cleared on
     * a slip with first_slip */
    const uint32_t ones = 0x01010101u;
    const uint32_t touch4 = ones * CDEM_PAIR_TOUCH, coh4 = ones * CDEM_PAIR_COHESIVE;
    const uint32_t bonded4 = ones * CDEM_PAIR_BONDED;
    const uint32_t coh_new4 = law->cohesive_new ? coh4 : 0u;
    const uint32_t slip_clears4 = law->first_slip ? coh4 : 0u;
    _Static_assert(CDEM_PAIR_COHESIVE == CDEM_PAIR_TOUCH << 1, "COHESIVE is the bit above TOUCH");
    /* local copies of the pointers (not restrict: the scalar fallbacks write the same arrays
     * through a), so that they stay in registers across the history stores */
    const int32_t *pi = a->pi, *pj = a->pj;
    const double *x = a->x, *y = a->y, *vx = a->vx, *vy = a->vy, *Rp = a->R;
    const uint8_t *cls = a->cls;
    uint8_t *hist = a->hist;
    double *xs = a->xs, *pfx = a->pfx, *pfy = a->pfy;
    const double *friction = law->friction, *cohesion = law->cohesion;
    const __m256d zero = _mm256_setzero_pd(), sign = _mm256_set1_pd(-0.0);
    const __m256d one = _mm256_set1_pd(1.0), kn = _mm256_set1_pd(law->kn);
    const __m256d ks = _mm256_set1_pd(law->ks), dt = _mm256_set1_pd(a->dt);
    const __m256i coh_bit = _mm256_set1_epi64x(CDEM_PAIR_COHESIVE);
    const __m128i below4 = _mm_set1_epi32(below);
    long p = p0, left = 0;
    for (; p + 4 <= p1; p += 4) {
        const __m128i i4 = _mm_loadu_si128((const __m128i *)(pi + p));
        const __m128i j4 = _mm_loadu_si128((const __m128i *)(pj + p));
        uint32_t h4;
        memcpy(&h4, hist + p, 4);
        const int own = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(below4, j4)));
        if (own != 0xF || (h4 & bonded4)) {
            left += group_scalar(a, p, p + 4, below);
            continue;
        }
        const __m256d dx = gather_diff(x, i4, j4);
        const __m256d dy = gather_diff(y, i4, j4);
        const __m256d r2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
        const __m256d R = _mm256_loadu_pd(Rp + p);
        /* separated: r2 >= R^2 or r2 <= 0 (ordered compares: a NaN distance counts as touching,
         * as in the scalar test) */
        const __m256d sep = _mm256_or_pd(_mm256_cmp_pd(r2, _mm256_mul_pd(R, R), _CMP_GE_OQ),
                                         _mm256_cmp_pd(r2, zero, _CMP_LE_OQ));
        const int sepm = _mm256_movemask_pd(sep);
        if (sepm == 0xF) {
            _mm256_storeu_pd(pfx + p, zero);
            _mm256_storeu_pd(pfy + p, zero);
            if (h4) {
                uint8_t hb[4];
                memcpy(hb, &h4, 4);
                separated_lanes(a, p, hb, r2, R, 0xF);
            }
            continue;
        }
        /* the touching lanes: cdem_contact_touching, operation by operation */
        const __m256d r = _mm256_sqrt_pd(r2);
        const __m256d inv = _mm256_div_pd(one, r);
        const __m256d nx = _mm256_mul_pd(dx, inv), ny = _mm256_mul_pd(dy, inv);
        const __m256d fn = _mm256_mul_pd(kn, _mm256_sub_pd(R, r));
        uint32_t hn4 = h4 | touch4 | (((~h4 & touch4) << 1) & coh_new4);
        __m256d ftx = zero, fty = zero;
        if (tangential) {
            const __m256d dvx = gather_diff(vx, i4, j4);
            const __m256d dvy = gather_diff(vy, i4, j4);
            const __m256d tx = _mm256_xor_pd(ny, sign), ty = nx;
            const __m256d xs0 = _mm256_loadu_pd(xs + p);
            __m256d sv = _mm256_add_pd(
                xs0,
                _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(dvx, tx), _mm256_mul_pd(dvy, ty)), dt));
            const __m256d spring = _mm256_mul_pd(ks, sv);
            uint32_t c4;
            memcpy(&c4, cls + p, 4);
            /* the class values: one class in all four lanes is the common case (broadcast);
             * else gathered */
            __m256d mu, coh;
            if (c4 == (c4 & 0xffu) * ones) {
                mu = _mm256_broadcast_sd(friction + (c4 & 0xffu));
                coh = _mm256_broadcast_sd(cohesion + (c4 & 0xffu));
            } else {
                const __m128i cl = _mm_cvtepu8_epi32(_mm_cvtsi32_si128((int)c4));
                mu = _mm256_i32gather_pd(friction, cl, 8);
                coh = _mm256_i32gather_pd(cohesion, cl, 8);
            }
            const __m256i cohesive = _mm256_cmpeq_epi64(
                _mm256_and_si256(_mm256_cvtepu8_epi64(_mm_cvtsi32_si128((int)hn4)), coh_bit),
                coh_bit);
            const __m256d c0 = _mm256_and_pd(coh, _mm256_castsi256_pd(cohesive));
            /* the law (common/laws/law_*.h): the force, the spring kept, the slip mask */
            const cdem_shear4 sh = lanes(spring, fn, mu, c0);
            const int slidm = _mm256_movemask_pd(sh.slid);
            sv = _mm256_blendv_pd(sv, _mm256_div_pd(sh.spring, ks), sh.slid);
            /* separated lanes keep their value here (set to 0 below when they have a history) */
            _mm256_storeu_pd(xs + p, _mm256_blendv_pd(sv, xs0, sep));
            hn4 &= ~(lane_bytes[slidm] & slip_clears4);
            ftx = _mm256_mul_pd(sh.force, tx);
            fty = _mm256_mul_pd(sh.force, ty);
        }
        const __m256d nfn = _mm256_xor_pd(fn, sign);
        const __m256d fx = _mm256_add_pd(_mm256_mul_pd(nfn, nx), ftx);
        const __m256d fy = _mm256_add_pd(_mm256_mul_pd(nfn, ny), fty);
        _mm256_storeu_pd(pfx + p, _mm256_blendv_pd(fx, zero, sep));
        _mm256_storeu_pd(pfy + p, _mm256_blendv_pd(fy, zero, sep));
        /* separated lanes keep their byte here; those with a history are finished below */
        const uint32_t sepb = lane_bytes[sepm];
        const uint32_t out4 = (hn4 & ~sepb) | (h4 & sepb);
        memcpy(hist + p, &out4, 4);
        if (h4 & sepb) {
            uint8_t hb[4];
            memcpy(hb, &h4, 4);
            separated_lanes(a, p, hb, r2, R, sepm);
        }
    }
    return left + group_scalar(a, p, p1, below);
}

/* The vector path of a law: its AVX2 kernel when it has one, else every pair by its scalar
 * kernel (the same bits; only the speed differs). */
AVX2 static inline __attribute__((always_inline)) long
pairs_of_law(const cdem_force_pairs *a, long p0, long p1, int32_t below, law_lanes lanes) {
    if (!lanes)
        return group_scalar(a, p0, p1, below);
    return pairs_with_law(a, p0, p1, below, lanes);
}

AVX2 static inline long pairs_by_law(const cdem_force_pairs *a, long p0, long p1, int32_t below) {
    switch (a->law->granular) { /* one case per row of laws.def */
#define CDEM_LAW(ID, word, description, scalar, lanes)                                             \
    case CDEM_LAW_##ID:                                                                            \
        return pairs_of_law(a, p0, p1, below, lanes);
#define CDEM_TEST_LAW CDEM_LAW
#include "laws/laws.def"
#undef CDEM_LAW
#undef CDEM_TEST_LAW
    default: /* no law: the scalar kernel says so */
        return group_scalar(a, p0, p1, below);
    }
}

/* Both functions called from the baseline code end with the upper halves of the vector
 * registers zero (vzeroupper; GCC 12 inserts none in these target("avx2") functions): else
 * every SSE instruction after them (the element loops of the pass, the list builds, the
 * output) runs with the upper halves in use, up to 4 times slower on an AMD EPYC (Zen 5;
 * docs/performance.md, "Speed on every CPU"). */
AVX2 long cdem_force_pairs_avx2(const cdem_force_pairs *a, long p0, long p1, int32_t below) {
    const long left = pairs_by_law(a, p0, p1, below);
    _mm256_zeroupper();
    return left;
}

AVX2 void cdem_force_scatter_avx2(const cdem_force_pairs *a, long p0, long p1, double *acc) {
    const int32_t *restrict pi = a->pi, *restrict pj = a->pj;
    const double *restrict pfx = a->pfx, *restrict pfy = a->pfy;
    double *restrict sum = acc;
    for (long p = p0; p < p1; p++) {
        const __m128d u = _mm_loadh_pd(_mm_load_sd(pfx + p), pfy + p);
        double *sj = sum + 2 * (long)pj[p], *si = sum + 2 * (long)pi[p];
        _mm_storeu_pd(sj, _mm_sub_pd(_mm_loadu_pd(sj), u));
        _mm_storeu_pd(si, _mm_add_pd(_mm_loadu_pd(si), u));
    }
    _mm256_zeroupper();
}

#else

int cdem_force_avx2_usable(void) {
    return 0;
}

long cdem_force_pairs_avx2(const cdem_force_pairs *a, long p0, long p1, int32_t below) {
    long left = 0;
    for (long p = p0; p < p1; p++) {
        if (a->pj[p] < below)
            cdem_force_pair_at(a, p);
        else
            left++;
    }
    return left;
}

void cdem_force_scatter_avx2(const cdem_force_pairs *a, long p0, long p1, double *acc) {
    for (long p = p0; p < p1; p++) {
        acc[2 * a->pj[p]] -= a->pfx[p];
        acc[2 * a->pj[p] + 1] -= a->pfy[p];
        acc[2 * a->pi[p]] += a->pfx[p];
        acc[2 * a->pi[p] + 1] += a->pfy[p];
    }
}

#endif
