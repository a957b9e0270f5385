/* force_avx2: the AVX2 kernels of the force pass (force_pairs.h, cdem_force_kernels), four
 * lanes of 256-bit registers:
 *   pairs    four pairs per step: the two elements of each pair loaded from the packed
 *            elements (pos4) and transposed into lanes, the distance, the touch test, the
 *            square root and the division, the normal and the trial tangential force, and the
 *            granular law's AVX2 kernel (common/laws/law_*.h: masks (blends) where its scalar
 *            kernel branches); the history bytes per lane. Each law has a loop of its own, its
 *            kernel inlined, chosen by one switch generated from laws.def; a law without an
 *            AVX2 kernel is evaluated pair by pair by its scalar kernel, never by another
 *            law's. A group of four falls back to the scalar kernel when one of its pairs is an
 *            intact bond (bonded model) or belongs to another chunk; so does the tail;
 *   scatter  the block's forces into the interleaved sums, one 128-bit add per pair end;
 *   finish, drift, pack   the element loops, four elements per step.
 * Compiled for the baseline x86-64 like the rest, with target("avx2") on these functions
 * only, so the scalar path still runs on any x86-64; elsewhere cdem_force_kernels_avx2() is
 * NULL and the scalar path is the only one. */
#include "force_pairs.h"

#include <string.h>

#if defined(__GNUC__) && defined(__x86_64__)

#include "force_lanes.h"

/* the laws' AVX2 kernels (common/laws/law.h) */
#define CDEM_LAW_LANES
#include "laws/law.h"
#include "laws/laws.def"

/* A byte mask per bit of a 4-bit lane mask: byte k of lane_bytes[m] is 0xff when bit k
 * of m is set (the history bytes of four pairs handled as one 32-bit word). */
static const uint32_t lane_bytes[16] = {0x00000000u, 0x000000ffu, 0x0000ff00u, 0x0000ffffu,
                                        0x00ff0000u, 0x00ff00ffu, 0x00ffff00u, 0x00ffffffu,
                                        0xff000000u, 0xff0000ffu, 0xff00ff00u, 0xff00ffffu,
                                        0xffff0000u, 0xffff00ffu, 0xffffff00u, 0xffffffffu};

/* The AVX2 kernel of a law (law.h): four contacts' trial spring force, normal force,
 * friction and cohesion in, the transmitted force, the spring kept and the slip mask out. */
typedef cdem_shear4 (*law_lanes)(__m256d spring, __m256d fn, __m256d mu, __m256d c0);

/* pairs_avx2 for the law whose AVX2 kernel is `lanes` (a constant at each call, so the kernel
 * is inlined and each law has a loop of its own). */
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
    const double *Rp = a->R, *pos4 = a->pos4;
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
        const __m128i j4 = _mm_loadu_si128((const __m128i *)(pj + p));
        uint32_t h4;
        memcpy(&h4, hist + p, 4);
        const int own = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(below4, j4)));
        if (own != 0xF || (h4 & bonded4)) {
            left += cdem_lanes_scalar(a, p, p + 4, below);
            continue;
        }
        __m256d dx, dy, dvx, dvy;
        cdem_lanes_diff4(pos4, pi + p, pj + p, &dx, &dy, &dvx, &dvy);
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
            if (h4)
                cdem_lanes_separated4(a, p, h4, r2, R, 0xF);
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
        if (h4 & sepb)
            cdem_lanes_separated4(a, p, h4, r2, R, sepm);
    }
    return left + cdem_lanes_scalar(a, p, p1, below);
}

/* The vector path of a law: its AVX2 kernel when it has one, else every pair by its scalar
 * kernel (the same bits; only the speed differs). */
AVX2 static inline __attribute__((always_inline)) long
pairs_of_law(const cdem_force_pairs *a, long p0, long p1, int32_t below, law_lanes lanes) {
    if (!lanes)
        return cdem_lanes_scalar(a, p0, p1, below);
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
        return cdem_lanes_scalar(a, p0, p1, below);
    }
}

/* Every kernel called from the baseline code leaves the upper halves of the vector registers
 * zero (vzeroupper; GCC does not always insert it in a function of a wider target): on the
 * AMD EPYC measured, every SSE instruction after a 256-bit one ran up to 4 times slower until
 * then (docs/performance.md, "Speed on every CPU"). */
AVX2 static long pairs_avx2(const cdem_force_pairs *a, long p0, long p1, int32_t below) {
    const long left = pairs_by_law(a, p0, p1, below);
    _mm256_zeroupper();
    return left;
}

/* The two 128-bit RMWs of pair p (force u): acc[pj] -= u, acc[pi] += u. */
#define SCATTER_ONE(p, u)                                                                          \
    do {                                                                                           \
        double *sj_ = sum + 2 * (long)pj[p], *si_ = sum + 2 * (long)pi[p];                         \
        _mm_storeu_pd(sj_, _mm_sub_pd(_mm_loadu_pd(sj_), (u)));                                    \
        _mm_storeu_pd(si_, _mm_add_pd(_mm_loadu_pd(si_), (u)));                                    \
    } while (0)

/* The slots are read four at a time, with the 256-bit loads the pairs kernel stored them with
 * (its groups of four start at the same p0), rather than one 64-bit load per slot and
 * component: 1-3 % less time per step on the AMD EPYC measured (docs/performance.md, "Speed
 * on every CPU"). The additions are those of the scalar loop, in slot order. */
AVX2 void cdem_force_avx2_scatter(const cdem_force_pairs *a, long p0, long p1, double *acc) {
    const int32_t *restrict pi = a->pi, *restrict pj = a->pj;
    const double *restrict pfx = a->pfx, *restrict pfy = a->pfy;
    double *restrict sum = acc;
    long p = p0;
    for (; p + 4 <= p1; p += 4) {
        const __m256d fx4 = _mm256_loadu_pd(pfx + p), fy4 = _mm256_loadu_pd(pfy + p);
        const __m256d even = _mm256_unpacklo_pd(fx4, fy4); /* pairs p, p + 2 */
        const __m256d odd = _mm256_unpackhi_pd(fx4, fy4);  /* pairs p + 1, p + 3 */
        SCATTER_ONE(p, _mm256_castpd256_pd128(even));
        SCATTER_ONE(p + 1, _mm256_castpd256_pd128(odd));
        SCATTER_ONE(p + 2, _mm256_extractf128_pd(even, 1));
        SCATTER_ONE(p + 3, _mm256_extractf128_pd(odd, 1));
    }
    for (; p < p1; p++)
        SCATTER_ONE(p, _mm_loadh_pd(_mm_load_sd(pfx + p), pfy + p));
    _mm256_zeroupper();
}
#undef SCATTER_ONE

AVX2 void cdem_force_avx2_pack(const double *x, const double *y, const double *vx, const double *vy,
                               long lo, long hi, double *pos4) {
    long i = lo;
    for (; i + 4 <= hi; i += 4)
        cdem_lanes_pack4(pos4 + 4 * i, _mm256_loadu_pd(x + i), _mm256_loadu_pd(y + i),
                         _mm256_loadu_pd(vx + i), _mm256_loadu_pd(vy + i));
    for (; i < hi; i++) {
        pos4[4 * i] = x[i];
        pos4[4 * i + 1] = y[i];
        pos4[4 * i + 2] = vx[i];
        pos4[4 * i + 3] = vy[i];
    }
    _mm256_zeroupper();
}

AVX2 long cdem_force_avx2_finish(const cdem_force_elements *e, const double *acc, double *vx,
                                 double *vy, double *fx, double *fy, long lo, long hi) {
    const cdem_lanes_finish k = cdem_lanes_finish_setup(e);
    long unstable = -1, i = lo;
    for (; i + 4 <= hi; i += 4) {
        const int bad = cdem_lanes_finish4(&k, e, acc, vx, vy, fx, fy, i);
        if (bad && unstable < 0)
            unstable = i + __builtin_ctz((unsigned)bad);
    }
    for (; i < hi; i++) {
        cdem_force_finish_one(e, i, acc[2 * i], acc[2 * i + 1], vx, vy, fx, fy);
        if (e->radius && unstable < 0 && cdem_force_unstable_one(e, i, vx, vy))
            unstable = i;
    }
    _mm256_zeroupper();
    return unstable;
}

AVX2 int cdem_force_avx2_drift(const cdem_force_drift_args *d, long lo, long hi) {
    int moved = 0;
    long i = lo;
    for (; i + 4 <= hi; i += 4)
        moved |= cdem_lanes_drift4(d, i);
    for (; i < hi; i++)
        moved |= cdem_force_drift_one(d, i);
    _mm256_zeroupper();
    return moved != 0;
}

/* 1 for a kernel, 0 for NULL: a function's name compared with NULL would be a warning */
static int has_lanes(law_lanes lanes) {
    return lanes != NULL;
}

int cdem_force_law_vectorised(cdem_granular_law law) {
    switch (law) { /* one case per row of laws.def */
#define CDEM_LAW(ID, word, description, scalar, lanes)                                             \
    case CDEM_LAW_##ID:                                                                            \
        return has_lanes(lanes);
#define CDEM_TEST_LAW CDEM_LAW
#include "laws/laws.def"
#undef CDEM_LAW
#undef CDEM_TEST_LAW
    default:
        return 0;
    }
}

const cdem_force_kernels *cdem_force_kernels_avx2(void) {
    static const cdem_force_kernels k = {pairs_avx2, cdem_force_avx2_scatter,
                                         cdem_force_avx2_finish, cdem_force_avx2_drift,
                                         cdem_force_avx2_pack};
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") ? &k : NULL;
}

#else

const cdem_force_kernels *cdem_force_kernels_avx2(void) {
    return NULL;
}

int cdem_force_law_vectorised(cdem_granular_law law) {
    (void)law;
    return 0; /* no vector path in this build */
}

#endif
