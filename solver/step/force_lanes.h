/* force_lanes: the four-lane (AVX2) pieces the vector kernels of the force pass share
 * (force_avx2.c): each the scalar
 * code of force_pairs.h on four pairs or four elements, the same IEEE operations in the same
 * order per lane, masks where the scalar code branches. Only for x86-64 with GCC or clang;
 * every function is inline with target("avx2"), so a file compiled for the baseline may
 * include it and call it from functions of a wider target. */
#ifndef CDEM_FORCE_LANES_H
#define CDEM_FORCE_LANES_H

#include "force_pairs.h"

#include <immintrin.h>
#include <string.h>

#define AVX2              __attribute__((target("avx2")))
#define CDEM_LANES_INLINE static inline __attribute__((always_inline, target("avx2")))

/* The AVX2 path's scatter and element loops (force_avx2.c; cdem_force_kernels says what each
 * does). Only call when cdem_force_kernels_avx2() is not NULL. */
void cdem_force_avx2_scatter(const cdem_force_pairs *a, long p0, long p1, double *acc);
long cdem_force_avx2_finish(const cdem_force_elements *e, const double *acc, double *vx, double *vy,
                            double *fx, double *fy, long lo, long hi);
int cdem_force_avx2_drift(const cdem_force_drift_args *d, long lo, long hi);
void cdem_force_avx2_pack(const double *x, const double *y, const double *vx, const double *vy,
                          long lo, long hi, double *pos4);

/* The pairs p..end-1 by the scalar kernel (those whose pj is below `below`); returns how
 * many were left to another chunk. */
static inline long cdem_lanes_scalar(const cdem_force_pairs *a, long p, long end, int32_t below) {
    long left = 0;
    for (long q = p; q < end; q++) {
        if (a->pj[q] < below)
            cdem_force_pair_at(a, q);
        else
            left++;
    }
    return left;
}

/* The separated lanes (mask) of the four pairs at p with a history (h4: their history bytes
 * before the step): what cdem_force_pair does for them (the force slots are written by the
 * caller). */
AVX2 static inline void cdem_lanes_separated4(const cdem_force_pairs *a, long p, uint32_t h4,
                                              __m256d r2, __m256d R, int mask) {
    double r2l[4], Rl[4];
    uint8_t hb[4];
    memcpy(hb, &h4, 4);
    _mm256_storeu_pd(r2l, r2);
    _mm256_storeu_pd(Rl, R);
    for (int k = 0; k < 4; k++)
        if (((mask >> k) & 1) && hb[k]) {
            a->hist[p + k] = cdem_contact_separated(hb[k], r2l[k], Rl[k]);
            a->xs[p + k] = 0.0;
        }
}

/* The differences pj - pi of x, y, vx, vy of four pairs whose elements are i[0..3], j[0..3],
 * from the packed elements (one 256-bit load per element), transposed into lanes. */
CDEM_LANES_INLINE void cdem_lanes_diff4(const double *pos4, const int32_t *i, const int32_t *j,
                                        __m256d *dx, __m256d *dy, __m256d *dvx, __m256d *dvy) {
    const __m256d d0 =
        _mm256_sub_pd(_mm256_load_pd(pos4 + 4 * (long)j[0]), _mm256_load_pd(pos4 + 4 * (long)i[0]));
    const __m256d d1 =
        _mm256_sub_pd(_mm256_load_pd(pos4 + 4 * (long)j[1]), _mm256_load_pd(pos4 + 4 * (long)i[1]));
    const __m256d d2 =
        _mm256_sub_pd(_mm256_load_pd(pos4 + 4 * (long)j[2]), _mm256_load_pd(pos4 + 4 * (long)i[2]));
    const __m256d d3 =
        _mm256_sub_pd(_mm256_load_pd(pos4 + 4 * (long)j[3]), _mm256_load_pd(pos4 + 4 * (long)i[3]));
    const __m256d t0 = _mm256_unpacklo_pd(d0, d1), t1 = _mm256_unpackhi_pd(d0, d1);
    const __m256d t2 = _mm256_unpacklo_pd(d2, d3), t3 = _mm256_unpackhi_pd(d2, d3);
    *dx = _mm256_permute2f128_pd(t0, t2, 0x20);
    *dy = _mm256_permute2f128_pd(t1, t3, 0x20);
    *dvx = _mm256_permute2f128_pd(t0, t2, 0x31);
    *dvy = _mm256_permute2f128_pd(t1, t3, 0x31);
}

/* The packed form of four elements (x, y, vx, vy in lanes) into pos4[0..15]. */
CDEM_LANES_INLINE void cdem_lanes_pack4(double *pos4, __m256d x, __m256d y, __m256d vx,
                                        __m256d vy) {
    const __m256d t0 = _mm256_unpacklo_pd(x, y), t1 = _mm256_unpackhi_pd(x, y);
    const __m256d t2 = _mm256_unpacklo_pd(vx, vy), t3 = _mm256_unpackhi_pd(vx, vy);
    _mm256_store_pd(pos4, _mm256_permute2f128_pd(t0, t2, 0x20));
    _mm256_store_pd(pos4 + 4, _mm256_permute2f128_pd(t1, t3, 0x20));
    _mm256_store_pd(pos4 + 8, _mm256_permute2f128_pd(t0, t2, 0x31));
    _mm256_store_pd(pos4 + 12, _mm256_permute2f128_pd(t1, t3, 0x31));
}

/* All bits set in the lanes of the four elements at flags whose flags have one of `bits`. */
CDEM_LANES_INLINE __m256d cdem_lanes_flags4(const uint32_t *flags, uint32_t bits) {
    const __m256i f = _mm256_cvtepu32_epi64(_mm_loadu_si128((const __m128i *)flags));
    const __m256i none =
        _mm256_cmpeq_epi64(_mm256_and_si256(f, _mm256_set1_epi64x(bits)), _mm256_setzero_si256());
    return _mm256_castsi256_pd(_mm256_xor_si256(none, _mm256_set1_epi64x(-1)));
}

/* The constants of the finish, broadcast. */
typedef struct {
    __m256d gx, gy, sf, ef, mid, hdt, c, chdt, one, dt2;
} cdem_lanes_finish;

CDEM_LANES_INLINE cdem_lanes_finish cdem_lanes_finish_setup(const cdem_force_elements *e) {
    return (cdem_lanes_finish){_mm256_set1_pd(e->lift_x),
                               _mm256_set1_pd(e->lift_y),
                               _mm256_set1_pd(e->surface_force),
                               _mm256_set1_pd(e->edge_force),
                               _mm256_set1_pd(e->edge_x_mid),
                               _mm256_set1_pd(e->hdt),
                               _mm256_set1_pd(e->c),
                               _mm256_set1_pd(e->c * e->hdt),
                               _mm256_set1_pd(1.0),
                               _mm256_set1_pd(e->dt2)};
}

/* cdem_force_finish_one of the four elements at i, from their sums in acc (interleaved x, y),
 * and the guard: returns its 4-bit mask of the elements that fail it (0 without e->radius). */
CDEM_LANES_INLINE int cdem_lanes_finish4(const cdem_lanes_finish *k, const cdem_force_elements *e,
                                         const double *acc, double *vx, double *vy, double *fx,
                                         double *fy, long i) {
    const __m256d sign = _mm256_set1_pd(-0.0);
    const __m256d a0 = _mm256_loadu_pd(acc + 2 * i), a1 = _mm256_loadu_pd(acc + 2 * i + 4);
    const __m256d sx = _mm256_permute4x64_pd(_mm256_unpacklo_pd(a0, a1), 0xD8);
    const __m256d sy = _mm256_permute4x64_pd(_mm256_unpackhi_pd(a0, a1), 0xD8);
    const __m256d bnd = cdem_lanes_flags4(e->flags + i, CDEM_FLAGS_BOUNDARY);
    const __m256d surf = cdem_lanes_flags4(e->flags + i, CDEM_FLAG_SURFACE);
    const __m256d edge = cdem_lanes_flags4(e->flags + i, CDEM_FLAG_BIAXIAL_EDGE);
    const __m256d m = _mm256_loadu_pd(e->mass + i);
    /* sy -= m lift_y + (surface ? surface_force : 0); sx -= m lift_x (the scalar finish's order) */
    const __m256d ty =
        _mm256_sub_pd(sy, _mm256_add_pd(_mm256_mul_pd(m, k->gy), _mm256_and_pd(k->sf, surf)));
    const __m256d sxg = _mm256_sub_pd(sx, _mm256_mul_pd(m, k->gx));
    /* sx += x < mid ? edge_force : -edge_force, on the edge elements */
    const __m256d left = _mm256_cmp_pd(_mm256_loadu_pd(e->x + i), k->mid, _CMP_LT_OQ);
    const __m256d tx = _mm256_blendv_pd(
        sxg, _mm256_add_pd(sxg, _mm256_blendv_pd(_mm256_xor_pd(k->ef, sign), k->ef, left)), edge);
    __m256d vxi = _mm256_loadu_pd(vx + i), vyi = _mm256_loadu_pd(vy + i);
    if (e->kick) {
        const __m256d inv = e->kick_finish ? _mm256_loadu_pd(e->kick_finish + i)
                                           : _mm256_div_pd(k->one, _mm256_add_pd(m, k->chdt));
        const __m256d nvx =
            _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(m, vxi), _mm256_mul_pd(k->hdt, tx)), inv);
        const __m256d nvy =
            _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(m, vyi), _mm256_mul_pd(k->hdt, ty)), inv);
        vxi = _mm256_blendv_pd(nvx, vxi, bnd);
        vyi = _mm256_blendv_pd(nvy, vyi, bnd);
        _mm256_storeu_pd(vx + i, vxi);
        _mm256_storeu_pd(vy + i, vyi);
    }
    _mm256_storeu_pd(fx + i,
                     _mm256_blendv_pd(_mm256_sub_pd(tx, _mm256_mul_pd(k->c, vxi)), sx, bnd));
    _mm256_storeu_pd(fy + i,
                     _mm256_blendv_pd(_mm256_sub_pd(ty, _mm256_mul_pd(k->c, vyi)), sy, bnd));
    if (!e->radius)
        return 0;
    const __m256d d2 =
        _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(vxi, vxi), _mm256_mul_pd(vyi, vyi)), k->dt2);
    const __m256d r = _mm256_loadu_pd(e->radius + i);
    return _mm256_movemask_pd(_mm256_cmp_pd(d2, _mm256_mul_pd(r, r), _CMP_GT_OQ));
}

/* cdem_force_drift_one of the four elements at i (and their packed form when d->pos4): 1 when
 * one of them moved too far. */
CDEM_LANES_INLINE int cdem_lanes_drift4(const cdem_force_drift_args *d, long i) {
    const __m256d dt = _mm256_set1_pd(d->dt);
    const __m256d bnd = cdem_lanes_flags4(d->flags + i, CDEM_FLAGS_BOUNDARY);
    const __m256d a =
        d->factor ? _mm256_loadu_pd(d->factor + i)
                  : _mm256_div_pd(_mm256_set1_pd(0.5 * d->dt), _mm256_loadu_pd(d->mass + i));
    const __m256d ox = _mm256_loadu_pd(d->x + i), oy = _mm256_loadu_pd(d->y + i);
    const __m256d ovx = _mm256_loadu_pd(d->vx + i), ovy = _mm256_loadu_pd(d->vy + i);
    const __m256d hvx = _mm256_add_pd(ovx, _mm256_mul_pd(a, _mm256_loadu_pd(d->fx + i)));
    const __m256d hvy = _mm256_add_pd(ovy, _mm256_mul_pd(a, _mm256_loadu_pd(d->fy + i)));
    const __m256d nx = _mm256_blendv_pd(_mm256_add_pd(ox, _mm256_mul_pd(dt, hvx)), ox, bnd);
    const __m256d ny = _mm256_blendv_pd(_mm256_add_pd(oy, _mm256_mul_pd(dt, hvy)), oy, bnd);
    const __m256d nvx = _mm256_blendv_pd(hvx, ovx, bnd), nvy = _mm256_blendv_pd(hvy, ovy, bnd);
    _mm256_storeu_pd(d->vx + i, nvx);
    _mm256_storeu_pd(d->vy + i, nvy);
    _mm256_storeu_pd(d->x + i, nx);
    _mm256_storeu_pd(d->y + i, ny);
    if (d->pos4)
        cdem_lanes_pack4(d->pos4 + 4 * i, nx, ny, nvx, nvy);
    if (!d->x0)
        return 0;
    const __m256d dx = _mm256_sub_pd(nx, _mm256_loadu_pd(d->x0 + i));
    const __m256d dy = _mm256_sub_pd(ny, _mm256_loadu_pd(d->y0 + i));
    const __m256d d2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
    return _mm256_movemask_pd(_mm256_cmp_pd(d2, _mm256_set1_pd(d->lim2), _CMP_NLE_UQ)) != 0;
}

#endif
