/* force_pairs: what the two pair loops of the force pass share, and nothing outside force.c
 * and force_avx2.c includes: the arrays of one pass, the scalar pair evaluation (the one
 * the whole code used before the vector path, and the vector path's fallback), and the
 * AVX2 block evaluation chosen at run time (force.h, "Paths").
 * Why a private header: force_avx2.c is compiled for the same baseline as everything else
 * and marks its functions target("avx2"), so the scalar kernel must be visible to it inline.
 * Bit-identity of the two paths: the AVX2 block does, lane by lane, the same IEEE operations
 * in the same order as pair_force (sqrt and division are correctly rounded in both, and the
 * build forbids fused multiply-adds, -ffp-contract=off), selects with masks where the scalar
 * code branches, and writes exactly the slots pair_force writes. Thread safety: one writer per
 * pair slot, as for the scalar path. Units: those of contact.h. */
#ifndef CDEM_FORCE_PAIRS_H
#define CDEM_FORCE_PAIRS_H

#include "contact.h"

#include <stdint.h>

/* The pair arrays of one force pass (pointers into the pair list and the state). */
typedef struct {
    const cdem_contact_law *law;
    double dt; /* s: the tangential increment (0: none) */
    const double *x, *y, *vx, *vy;
    const int32_t *pi, *pj;
    const double *R;
    const uint8_t *cls;
    uint8_t *hist;
    double *xs, *pfx, *pfy;
} cdem_force_pairs;

/* Force of pair p on its pi into the slot pfx[p], pfy[p] (zero when it does not touch):
 * the common case of a list pair that does not touch is settled here, everything else by
 * the one contact kernel (contact.h); a branch-free evaluation of every list pair is slower
 * (docs/performance.md, "Choices in the force pass"). */
static CDEM_INLINE void cdem_force_pair(const cdem_contact_law *restrict law, long p, double dx,
                                        double dy, double dvx, double dvy,
                                        const double *restrict Rp, const uint8_t *restrict cls,
                                        uint8_t *restrict hist, double *restrict xs,
                                        double *restrict pfx, double *restrict pfy, double dt) {
    const double R = Rp[p];
    const uint8_t h = hist[p];
    const double r2 = dx * dx + dy * dy;
    if (!(h & CDEM_PAIR_BONDED)) {
        if (r2 >= R * R || r2 <= 0.0) {
            /* separated: xs != 0 only with h != 0 */
            pfx[p] = 0.0;
            pfy[p] = 0.0;
            if (h) {
                hist[p] = cdem_contact_separated(h, r2, R);
                xs[p] = 0.0;
            }
            return;
        }
        cdem_contact_touching(law, cls[p], r2, dx, dy, R, dvx, dvy, dt, &xs[p], &hist[p], &pfx[p],
                              &pfy[p]);
        return;
    }
    cdem_contact_eval(law, cls[p], dx, dy, R, dvx, dvy, dt, &xs[p], &hist[p], &pfx[p], &pfy[p]);
}

/* cdem_force_pair for pair p of the arrays a. */
static CDEM_INLINE void cdem_force_pair_at(const cdem_force_pairs *a, long p) {
    const int32_t i = a->pi[p], j = a->pj[p];
    cdem_force_pair(a->law, p, a->x[j] - a->x[i], a->y[j] - a->y[i], a->vx[j] - a->vx[i],
                    a->vy[j] - a->vy[i], a->R, a->cls, a->hist, a->xs, a->pfx, a->pfy, a->dt);
}

/* 1 when this build has the AVX2 block evaluation and the CPU runs it. */
int cdem_force_avx2_usable(void);

/* Evaluates every pair p in p0..p1-1 whose pj is below `below` (the others are left
 * untouched: another chunk evaluates them), exactly as cdem_force_pair would, four at a time
 * in AVX2 lanes. Returns the number of pairs left (pj >= below). Only call when
 * cdem_force_avx2_usable(). */
long cdem_force_pairs_avx2(const cdem_force_pairs *a, long p0, long p1, int32_t below);

/* The scatter of the pairs p0..p1-1 (none of them a cross pair) into the interleaved sums
 * acc (acc[2e], acc[2e+1] = x and y of element e): acc[pj] -= f, acc[pi] += f in slot order,
 * both components in one 128-bit operation (the same two IEEE additions). Only call when
 * cdem_force_avx2_usable(). */
void cdem_force_scatter_avx2(const cdem_force_pairs *a, long p0, long p1, double *acc);

#endif
