/* force_pairs: what the force pass's paths share, and nothing outside force.c and its vector
 * files (force_avx2.c) includes: the arrays of one pass, the scalar pair
 * evaluation (the one the whole code used before the vector paths, and their fallback), the
 * scalar element drift and finish (the scalar path, and the vector loops' tails), and the
 * vector kernels chosen at run time (force.h, "Paths").
 * Why a private header: the vector files are compiled for the same baseline as everything
 * else and mark their functions target("avx2"), so the scalar kernels
 * must be visible to them inline.
 * Bit-identity of the paths: a vector kernel does, lane by lane, the same IEEE operations in
 * the same order as the scalar code here (sqrt and division are correctly rounded in both,
 * and the build forbids fused multiply-adds, -ffp-contract=off), selects with masks where
 * the scalar code branches, and writes exactly what the scalar code writes (a lane it must
 * leave alone is stored with the value it loaded). Thread safety: one writer per pair slot
 * and per element, as for the scalar path. Units: those of contact.h. */
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
    /* the vector paths' packed elements: pos4[4e .. 4e+3] = x, y, vx, vy of element e, 32-byte
     * aligned, current for every element whose pairs a vector kernel evaluates (the kernels
     * read both elements of a pair with one 256-bit load each, where gathers of the four
     * arrays are microcoded and slow on several cores: docs/performance.md, "Speed on every
     * CPU") */
    const double *pos4;
} cdem_force_pairs;

/* What an element's finish reads besides its contact-force sum: the kick, the loads, the
 * element arrays of the pass and the run loop's guard (the written arrays are passed apart,
 * as restrict parameters: docs/performance.md, "Choices in the force pass"). */
typedef struct {
    int kick;      /* 1: the damped second half kick */
    double hdt, c; /* s, dt / 2; N s/m, the damping of the step */
    /* m/s^2: minus gravity's acceleration, (0 - gx, 0 - gy): the finish subtracts m times it
     * from the sum. Subtracting m x (+0) leaves a sum's bits as they are (also a -0 sum), so
     * the default (0, -g), here (+0, g), gives the bits of gravity as a scalar along -y */
    double lift_x, lift_y;
    double surface_force;      /* N: in -y on elements flagged CDEM_FLAG_SURFACE */
    double edge_force;         /* N: on CDEM_FLAG_BIAXIAL_EDGE, +x left of edge_x_mid */
    double edge_x_mid;         /* m */
    const double *mass, *x;    /* kg per metre; m (the edge load's side) */
    const double *kick_finish; /* 1 / (m + c dt/2) per element (the stepper's), or NULL */
    const uint32_t *flags;
    const double *radius; /* the unstable-motion guard's radii, NULL: guard off */
    double dt2;           /* s^2: the step squared, for the guard */
} cdem_force_elements;

/* Finishes element i from its contact-force sum (sx, sy): gravity and the other loads, the
 * damped second half kick (when e->kick) of its velocity (vx, vy), and the total force
 * stored in fx, fy. Boundary elements keep the sum. */
static CDEM_INLINE void cdem_force_finish_one(const cdem_force_elements *e, long i, double sx,
                                              double sy, double *restrict vx, double *restrict vy,
                                              double *restrict fx, double *restrict fy) {
    const uint32_t fl = e->flags[i];
    if (fl & CDEM_FLAGS_BOUNDARY) {
        fx[i] = sx;
        fy[i] = sy;
        return;
    }
    const double m = e->mass[i];
    sx -= m * e->lift_x;
    sy -= m * e->lift_y + ((fl & CDEM_FLAG_SURFACE) ? e->surface_force : 0.0);
    if (fl & CDEM_FLAG_BIAXIAL_EDGE)
        sx += e->x[i] < e->edge_x_mid ? e->edge_force : -e->edge_force;
    if (e->kick) {
        /* v = (v_half + hdt/m F) / (1 + c hdt/m), with 1 / (m + c hdt) from kick_finish */
        const double inv = e->kick_finish ? e->kick_finish[i] : 1.0 / (m + e->c * e->hdt);
        vx[i] = (m * vx[i] + e->hdt * sx) * inv;
        vy[i] = (m * vy[i] + e->hdt * sy) * inv;
    }
    fx[i] = sx - e->c * vx[i];
    fy[i] = sy - e->c * vy[i];
}

/* The run loop's guard for element i (after its finish): 1 when it moves more than its
 * radius in a step. */
static CDEM_INLINE int cdem_force_unstable_one(const cdem_force_elements *e, long i,
                                               const double *restrict vx,
                                               const double *restrict vy) {
    const double d2 = (vx[i] * vx[i] + vy[i] * vy[i]) * e->dt2;
    return d2 > e->radius[i] * e->radius[i];
}

/* The drift of the force pass (force.h, cdem_force_drift): the arrays and constants. */
typedef struct {
    double *x, *y, *vx, *vy;
    const double *fx, *fy, *mass;
    const uint32_t *flags;
    const double *factor;  /* (dt/2) / m per element, or NULL: divide */
    double dt;             /* s */
    const double *x0, *y0; /* positions of the last build (the rebuild test), or NULL: none */
    double lim2;           /* m^2: the rebuild test's squared distance */
    double *pos4;          /* a vector drift also packs the elements (cdem_force_pairs), or NULL */
} cdem_force_drift_args;

/* The first half kick and drift of element i (free elements only), and the rebuild test of
 * its position: returns 1 when it moved more than sqrt(lim2) since the last build. */
static CDEM_INLINE int cdem_force_drift_one(const cdem_force_drift_args *d, long i) {
    double xi = d->x[i], yi = d->y[i];
    if (!(d->flags[i] & CDEM_FLAGS_BOUNDARY)) {
        const double a = d->factor ? d->factor[i] : (0.5 * d->dt) / d->mass[i]; /* the same bits */
        const double hvx = d->vx[i] + a * d->fx[i], hvy = d->vy[i] + a * d->fy[i];
        d->vx[i] = hvx;
        d->vy[i] = hvy;
        xi += d->dt * hvx;
        yi += d->dt * hvy;
        d->x[i] = xi;
        d->y[i] = yi;
    }
    if (d->pos4) {
        d->pos4[4 * i] = xi;
        d->pos4[4 * i + 1] = yi;
        d->pos4[4 * i + 2] = d->vx[i];
        d->pos4[4 * i + 3] = d->vy[i];
    }
    if (!d->x0)
        return 0;
    const double dx = xi - d->x0[i], dy = yi - d->y0[i];
    return !(dx * dx + dy * dy <= d->lim2); /* cdem_neighbour_moved_one; NaN counts as moved */
}

/* Force of pair p on its pi into the slot pfx[p], pfy[p] (zero when it does not touch):
 * the common case of a list pair that does not touch is settled here, everything else by
 * the one contact kernel (contact.h); a branch-free evaluation of every list pair is slower
 * (docs/performance.md, "Choices in the force pass"). stateful: a constant, 1 in the loop of
 * the laws with state (coefficients or history slots; slots: the list's, law->slot_count a
 * pair, or NULL), 0 in the loops of all the others, which then have no code of the laws with
 * state (CDEM_LAW_CALL) and are the instructions they were before laws had state: with it
 * (a slot pointer computed and kept in every loop, the laws with state in the kernel's
 * switch) the scalar path ran 0.5-1 % more instructions. */
static CDEM_INLINE void cdem_force_pair(const cdem_contact_law *restrict law, long p, double dx,
                                        double dy, double dvx, double dvy,
                                        const double *restrict Rp, const uint8_t *restrict cls,
                                        uint8_t *restrict hist, double *restrict xs,
                                        double *restrict slots, double *restrict pfx,
                                        double *restrict pfy, double dt, int stateful) {
    const double R = Rp[p];
    const uint8_t h = hist[p];
    const double r2 = dx * dx + dy * dy;
    /* the pair's history slots (only a kernel with slots reads them) */
    double *const own = stateful && slots ? slots + p * law->slot_count : NULL;
    if (!(h & CDEM_PAIR_BONDED)) {
        if (r2 >= R * R || r2 <= 0.0) {
            /* separated: xs and the slots != 0 only with h != 0 */
            pfx[p] = 0.0;
            pfy[p] = 0.0;
            if (h) {
                hist[p] = cdem_contact_separated(h, r2, R);
                xs[p] = 0.0;
                if (own)
                    cdem_contact_forget_slots(law, own);
            }
            return;
        }
        cdem_contact_touching_of(law, cls[p], r2, dx, dy, R, dvx, dvy, dt, &xs[p], &hist[p], own,
                                 &pfx[p], &pfy[p], stateful);
        return;
    }
    cdem_contact_eval(law, cls[p], dx, dy, R, dvx, dvy, dt, &xs[p], &hist[p], own, &pfx[p],
                      &pfy[p]);
}

/* cdem_force_pair for pair p of the arrays a, for a law without state (the vector paths':
 * a law with state is evaluated by the scalar loop of its own, force.c). */
static CDEM_INLINE void cdem_force_pair_at(const cdem_force_pairs *a, long p) {
    const int32_t i = a->pi[p], j = a->pj[p];
    cdem_force_pair(a->law, p, a->x[j] - a->x[i], a->y[j] - a->y[i], a->vx[j] - a->vx[i],
                    a->vy[j] - a->vy[i], a->R, a->cls, a->hist, a->xs, NULL, a->pfx, a->pfy, a->dt,
                    0);
}

/* The kernels of a vector path (force.h, "Paths"). Each gives the bits of the scalar code
 * above. */
typedef struct {
    /* Evaluates every pair p in p0..p1-1 whose pj is below `below` (the others are left
     * untouched: another chunk evaluates them), exactly as cdem_force_pair would, from
     * a->pos4. Returns the number of pairs left (pj >= below). */
    long (*pairs)(const cdem_force_pairs *a, long p0, long p1, int32_t below);
    /* The scatter of the pairs p0..p1-1 (none of them a cross pair) into the interleaved sums
     * acc (acc[2e], acc[2e+1] = x and y of element e): acc[pj] -= f, acc[pi] += f in slot
     * order, both components in one 128-bit operation (the same two IEEE additions). */
    void (*scatter)(const cdem_force_pairs *a, long p0, long p1, double *acc);
    /* cdem_force_finish_one of the elements lo..hi-1 from their sums in acc, and their guard
     * (e->radius): returns the lowest index that fails it, or -1. */
    long (*finish)(const cdem_force_elements *e, const double *acc, double *vx, double *vy,
                   double *fx, double *fy, long lo, long hi);
    /* cdem_force_drift_one of the elements lo..hi-1: 1 when one of them moved too far. */
    int (*drift)(const cdem_force_drift_args *d, long lo, long hi);
    /* pos4 of the elements lo..hi-1 from x, y, vx, vy (a pass without its drift). */
    void (*pack)(const double *x, const double *y, const double *vx, const double *vy, long lo,
                 long hi, double *pos4);
} cdem_force_kernels;

/* The AVX2 kernels (force_avx2.c), or NULL when this build or this CPU has none. */
const cdem_force_kernels *cdem_force_kernels_avx2(void);
/* The AVX-512 pair kernel with the AVX2 element loops (force_avx512.c), or NULL. */
const cdem_force_kernels *cdem_force_kernels_avx512(void);

#endif
