/* force_avx512: the AVX-512 pair kernel of the force pass (force_pairs.h, cdem_force_kernels):
 * force_avx2.c's pair kernel on eight pairs per step, in 512-bit registers. The elements are
 * loaded from the packed copy and transposed four at a time (force_lanes.h); the distance, the
 * touch test, the square root, the divisions, the normal and trial tangential force run in
 * eight lanes (the square root and the division take as long for eight lanes as for four on
 * the AMD EPYC measured: docs/performance.md, "Speed on every CPU"); the granular law's AVX2
 * kernel runs on the two halves. Lane by lane the same IEEE operations in the same order as
 * the scalar code, masks where it branches: the same bits. The scatter and the element loops
 * are the AVX2 path's. Compiled for the baseline x86-64 with a target attribute on these
 * functions only; cdem_force_kernels_avx512() is NULL where the CPU lacks AVX-512 F/DQ/VL. */
#include "force_pairs.h"

#include <string.h>

#if defined(__GNUC__) && defined(__x86_64__)

#include "force_lanes.h"

#define CDEM_LAW_LANES
#include "laws/law.h"
#include "laws/laws.def"

#define AVX512 __attribute__((target("avx2,avx512f,avx512dq,avx512vl")))

typedef cdem_shear4 (*law_lanes)(__m256d spring, __m256d fn, __m256d mu, __m256d c0);

/* A byte mask per bit of a 4-bit lane mask (as force_avx2.c's), and of an 8-bit one. */
static const uint32_t lane_bytes[16] = {0x00000000u, 0x000000ffu, 0x0000ff00u, 0x0000ffffu,
                                        0x00ff0000u, 0x00ff00ffu, 0x00ffff00u, 0x00ffffffu,
                                        0xff000000u, 0xff0000ffu, 0xff00ff00u, 0xff00ffffu,
                                        0xffff0000u, 0xffff00ffu, 0xffffff00u, 0xffffffffu};
static inline uint64_t lane_bytes8(unsigned m) {
    return lane_bytes[m & 15u] | ((uint64_t)lane_bytes[(m >> 4) & 15u] << 32);
}

/* Stores of eight slots as two 256-bit halves: the scatter reads them with 256-bit loads, and
 * a load of half of a 512-bit store still in the store queue may wait for it to commit. */
AVX512 static inline void store8(double *d, __m512d v) {
    _mm256_storeu_pd(d, _mm512_castpd512_pd256(v));
    _mm256_storeu_pd(d + 4, _mm512_extractf64x4_pd(v, 1));
}

AVX512 static inline __m512d join(__m256d lo, __m256d hi) {
    return _mm512_insertf64x4(_mm512_castpd256_pd512(lo), hi, 1);
}

/* cdem_lanes_separated4 of both halves (mask: 8 bits; h8: the eight history bytes). */
AVX512 static inline void separated8(const cdem_force_pairs *a, long p, uint64_t h8, __m512d r2,
                                     __m512d R, unsigned mask) {
    cdem_lanes_separated4(a, p, (uint32_t)h8, _mm512_castpd512_pd256(r2), _mm512_castpd512_pd256(R),
                          (int)(mask & 15u));
    cdem_lanes_separated4(a, p + 4, (uint32_t)(h8 >> 32), _mm512_extractf64x4_pd(r2, 1),
                          _mm512_extractf64x4_pd(R, 1), (int)(mask >> 4));
}

AVX512 static inline __attribute__((always_inline)) long
pairs8_with_law(const cdem_force_pairs *a, long p0, long p1, int32_t below, law_lanes lanes) {
    const cdem_contact_law *law = a->law;
    const int tangential = law->model == CDEM_MATERIAL_GRANULAR && law->ks > 0.0;
    const uint64_t ones = 0x0101010101010101u;
    const uint64_t touch8 = ones * CDEM_PAIR_TOUCH, coh8 = ones * CDEM_PAIR_COHESIVE;
    const uint64_t bonded8 = ones * CDEM_PAIR_BONDED;
    const uint64_t coh_new8 = law->cohesive_new ? coh8 : 0u;
    const uint64_t slip_clears8 = law->first_slip ? coh8 : 0u;
    const int32_t *pi = a->pi, *pj = a->pj;
    const double *Rp = a->R, *pos4 = a->pos4;
    const uint8_t *cls = a->cls;
    uint8_t *hist = a->hist;
    double *xs = a->xs, *pfx = a->pfx, *pfy = a->pfy;
    const double *friction = law->friction, *cohesion = law->cohesion;
    const __m512d zero = _mm512_setzero_pd(), sign = _mm512_set1_pd(-0.0);
    const __m512d one = _mm512_set1_pd(1.0), kn = _mm512_set1_pd(law->kn);
    const __m512d ks = _mm512_set1_pd(law->ks), dt = _mm512_set1_pd(a->dt);
    const __m512i coh_bit = _mm512_set1_epi64(CDEM_PAIR_COHESIVE);
    const __m256i below8 = _mm256_set1_epi32(below);
    long p = p0, left = 0;
    for (; p + 8 <= p1; p += 8) {
        const __m256i j8 = _mm256_loadu_si256((const __m256i *)(pj + p));
        uint64_t h8;
        memcpy(&h8, hist + p, 8);
        const int own = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(below8, j8)));
        if (own != 0xFF || (h8 & bonded8)) {
            left += cdem_lanes_scalar(a, p, p + 8, below);
            continue;
        }
        __m256d dx0, dy0, dvx0, dvy0, dx1, dy1, dvx1, dvy1;
        cdem_lanes_diff4(pos4, pi + p, pj + p, &dx0, &dy0, &dvx0, &dvy0);
        cdem_lanes_diff4(pos4, pi + p + 4, pj + p + 4, &dx1, &dy1, &dvx1, &dvy1);
        const __m512d dx = join(dx0, dx1), dy = join(dy0, dy1);
        const __m512d r2 = _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy));
        const __m512d R = _mm512_loadu_pd(Rp + p);
        const __mmask8 sepk = _mm512_cmp_pd_mask(r2, _mm512_mul_pd(R, R), _CMP_GE_OQ) |
                              _mm512_cmp_pd_mask(r2, zero, _CMP_LE_OQ);
        const unsigned sepm = (unsigned)sepk;
        if (sepm == 0xFF) {
            store8(pfx + p, zero);
            store8(pfy + p, zero);
            if (h8)
                separated8(a, p, h8, r2, R, 0xFF);
            continue;
        }
        const __m512d r = _mm512_sqrt_pd(r2);
        const __m512d inv = _mm512_div_pd(one, r);
        const __m512d nx = _mm512_mul_pd(dx, inv), ny = _mm512_mul_pd(dy, inv);
        const __m512d fn = _mm512_mul_pd(kn, _mm512_sub_pd(R, r));
        uint64_t hn8 = h8 | touch8 | (((~h8 & touch8) << 1) & coh_new8);
        __m512d ftx = zero, fty = zero;
        if (tangential) {
            const __m512d dvx = join(dvx0, dvx1), dvy = join(dvy0, dvy1);
            const __m512d tx = _mm512_xor_pd(ny, sign), ty = nx;
            const __m512d xs0 = _mm512_loadu_pd(xs + p);
            __m512d sv = _mm512_add_pd(
                xs0,
                _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(dvx, tx), _mm512_mul_pd(dvy, ty)), dt));
            const __m512d spring = _mm512_mul_pd(ks, sv);
            uint64_t c8;
            memcpy(&c8, cls + p, 8);
            __m512d mu, coh;
            if (c8 == (c8 & 0xffu) * ones) {
                mu = _mm512_set1_pd(friction[c8 & 0xffu]);
                coh = _mm512_set1_pd(cohesion[c8 & 0xffu]);
            } else {
                const __m256i cl = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128((long long)c8));
                mu = _mm512_i32gather_pd(cl, friction, 8);
                coh = _mm512_i32gather_pd(cl, cohesion, 8);
            }
            const __mmask8 cohesive = _mm512_cmpeq_epi64_mask(
                _mm512_and_si512(_mm512_cvtepu8_epi64(_mm_cvtsi64_si128((long long)hn8)), coh_bit),
                coh_bit);
            const __m512d c0 = _mm512_maskz_mov_pd(cohesive, coh);
            const cdem_shear4 s0 = lanes(_mm512_castpd512_pd256(spring), _mm512_castpd512_pd256(fn),
                                         _mm512_castpd512_pd256(mu), _mm512_castpd512_pd256(c0));
            const cdem_shear4 s1 =
                lanes(_mm512_extractf64x4_pd(spring, 1), _mm512_extractf64x4_pd(fn, 1),
                      _mm512_extractf64x4_pd(mu, 1), _mm512_extractf64x4_pd(c0, 1));
            const unsigned slidm = (unsigned)_mm256_movemask_pd(s0.slid) |
                                   ((unsigned)_mm256_movemask_pd(s1.slid) << 4);
            const __m512d force = join(s0.force, s1.force);
            sv = _mm512_mask_div_pd(sv, (__mmask8)slidm, join(s0.spring, s1.spring), ks);
            _mm512_storeu_pd(xs + p, _mm512_mask_blend_pd(sepk, sv, xs0));
            hn8 &= ~(lane_bytes8(slidm) & slip_clears8);
            ftx = _mm512_mul_pd(force, tx);
            fty = _mm512_mul_pd(force, ty);
        }
        const __m512d nfn = _mm512_xor_pd(fn, sign);
        const __m512d fx = _mm512_add_pd(_mm512_mul_pd(nfn, nx), ftx);
        const __m512d fy = _mm512_add_pd(_mm512_mul_pd(nfn, ny), fty);
        store8(pfx + p, _mm512_mask_blend_pd(sepk, fx, zero));
        store8(pfy + p, _mm512_mask_blend_pd(sepk, fy, zero));
        const uint64_t sepb = lane_bytes8(sepm);
        const uint64_t out8 = (hn8 & ~sepb) | (h8 & sepb);
        memcpy(hist + p, &out8, 8);
        if (h8 & sepb)
            separated8(a, p, h8, r2, R, sepm);
    }
    return left + cdem_lanes_scalar(a, p, p1, below);
}

AVX512 static inline __attribute__((always_inline)) long
pairs8_of_law(const cdem_force_pairs *a, long p0, long p1, int32_t below, law_lanes lanes) {
    if (!lanes)
        return cdem_lanes_scalar(a, p0, p1, below);
    return pairs8_with_law(a, p0, p1, below, lanes);
}

AVX512 static long pairs_avx512(const cdem_force_pairs *a, long p0, long p1, int32_t below) {
    long left;
    switch (a->law->granular) { /* one case per row of laws.def */
#define CDEM_LAW(ID, word, description, scalar, lanes)                                             \
    case CDEM_LAW_##ID:                                                                            \
        left = pairs8_of_law(a, p0, p1, below, lanes);                                             \
        break;
#define CDEM_TEST_LAW CDEM_LAW
#include "laws/laws.def"
#undef CDEM_LAW
#undef CDEM_TEST_LAW
    default: /* no law: the scalar kernel says so */
        left = cdem_lanes_scalar(a, p0, p1, below);
    }
    _mm256_zeroupper(); /* as every kernel (force_avx2.c) */
    return left;
}

const cdem_force_kernels *cdem_force_kernels_avx512(void) {
    static const cdem_force_kernels k = {pairs_avx512, cdem_force_avx2_scatter,
                                         cdem_force_avx2_finish, cdem_force_avx2_drift,
                                         cdem_force_avx2_pack};
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("avx512f") &&
                   __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl")
               ? &k
               : NULL;
}

#else

const cdem_force_kernels *cdem_force_kernels_avx512(void) {
    return NULL;
}

#endif
