/* neighbour_avx2: the list build's distance test four candidates at a time (neighbour.h,
 * cdem_neighbour_near_avx2). The candidates of a row of cells are read from the build's
 * cell-ordered copies of the positions and radii (contiguous: one 256-bit load each, no
 * gather); each lane does the IEEE operations of the scalar test in neighbour.c in the same
 * order (R = ri + rj, cut = R rf + skin, dx^2 + dy^2 against cut^2; -ffp-contract=off), so
 * the same candidates pass with the same R, in the same order. Compiled for the baseline
 * x86-64 with target("avx2") on this function only; elsewhere it is not built and
 * cdem_neighbour_avx2_usable() is 0. */
#include "neighbour.h"

#if defined(__GNUC__) && defined(__x86_64__)

#include <immintrin.h>

int cdem_neighbour_avx2_usable(void) {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2");
}

__attribute__((target("avx2"))) size_t cdem_neighbour_near_avx2(const cdem_neighbour_cells *c,
                                                                int32_t i, double xi, double yi,
                                                                double ri, int32_t k0, int32_t k1,
                                                                int32_t *out_k, double *out_R) {
    const double *restrict cx = c->x, *restrict cy = c->y, *restrict cr = c->r;
    const int32_t *restrict item = c->item;
    const __m256d vxi = _mm256_set1_pd(xi), vyi = _mm256_set1_pd(yi), vri = _mm256_set1_pd(ri);
    const __m256d rf = _mm256_set1_pd(c->reach_factor), skin = _mm256_set1_pd(c->skin);
    const __m128i vi = _mm_set1_epi32(i);
    size_t m = 0;
    int32_t k = k0;
    for (; k + 4 <= k1; k += 4) {
        /* j > i (the lanes of elements at or below i are not candidates) */
        const __m128i j4 = _mm_loadu_si128((const __m128i *)(item + k));
        const int above = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(j4, vi)));
        if (!above)
            continue;
        const __m256d R = _mm256_add_pd(vri, _mm256_loadu_pd(cr + k));
        const __m256d cut = _mm256_add_pd(_mm256_mul_pd(R, rf), skin);
        const __m256d dx = _mm256_sub_pd(_mm256_loadu_pd(cx + k), vxi);
        const __m256d dy = _mm256_sub_pd(_mm256_loadu_pd(cy + k), vyi);
        const __m256d d2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
        /* the scalar code skips when d2 >= cut^2: keep "not >=" (a NaN is kept, as there) */
        int keep = _mm256_movemask_pd(_mm256_cmp_pd(d2, _mm256_mul_pd(cut, cut), _CMP_NGE_UQ));
        keep &= above;
        if (!keep)
            continue;
        double Rl[4];
        _mm256_storeu_pd(Rl, R);
        while (keep) {
            const int l = __builtin_ctz((unsigned)keep);
            keep &= keep - 1;
            out_k[m] = k + l;
            out_R[m] = Rl[l];
            m++;
        }
    }
    for (; k < k1; k++) {
        if (item[k] <= i)
            continue;
        const double R = ri + cr[k];
        const double cut = R * c->reach_factor + c->skin;
        const double dx = cx[k] - xi, dy = cy[k] - yi;
        if (dx * dx + dy * dy >= cut * cut)
            continue;
        out_k[m] = k;
        out_R[m] = R;
        m++;
    }
    _mm256_zeroupper(); /* the baseline code after it pays for dirty upper halves (force_avx2.c) */
    return m;
}

#else

int cdem_neighbour_avx2_usable(void) {
    return 0;
}

size_t cdem_neighbour_near_avx2(const cdem_neighbour_cells *c, int32_t i, double xi, double yi,
                                double ri, int32_t k0, int32_t k1, int32_t *out_k, double *out_R) {
    (void)c, (void)i, (void)xi, (void)yi, (void)ri, (void)k0, (void)k1, (void)out_k, (void)out_R;
    return 0;
}

#endif
