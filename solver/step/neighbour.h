/* neighbour: the pair list of the solver. A cell grid (cell size >= the largest interaction
 * reach + skin) finds the candidate pairs at each rebuild; the Verlet list keeps every pair
 * whose gap is below the skin, and stays valid until some element has moved more than half
 * the skin since the build (then cdem_neighbour_needs_rebuild says so). Never all-pairs.
 * Each pair carries its contact history (contact.h: the flags, Xs, and the granular law's
 * history slots, slot_count doubles a pair, none and nothing allocated for a law without)
 * and a force slot (one writer per slot); fixed per-element slot lists (CSR) make the
 * per-element force sums independent of the thread count. At a rebuild the histories are
 * carried over by element id pair, so they survive re-sorting and element removal; every
 * `resort_every` builds the state arrays are permuted into cell order (memory locality).
 * Between builds the caller may only append elements to the state (removal goes through
 * the keep argument of the build). Ownership: cdem_neighbour owns its buffers (grown geometrically,
 * only at build time); it never owns the state. Thread safety: one build at a time (it
 * threads its pair enumeration and its other long passes itself: the same list for any thread
 * count); readers may share the lists. Units: m. */
#ifndef CDEM_NEIGHBOUR_H
#define CDEM_NEIGHBOUR_H

#include "cdem_error.h"
#include "snapshot.h"
#include "state.h"

#include <stddef.h>
#include <stdint.h>

/* Carried contact history of one pair across a build, by the pair's element indices before
 * the build (mapped through removal and re-sorting; ids never change meaning). Its law's
 * history slots travel beside it (cdem_neighbour carry_slots, the same index). */
typedef struct {
    int32_t i, j; /* element indices before the build, i < j */
    double xs;    /* tangential displacement, m */
    uint8_t hist; /* CDEM_PAIR_* flags */
} cdem_pair_carry;

/* Largest number of threads the list build uses (more are ignored: the build stays on at
 * most this many). */
#define CDEM_NB_MAX_THREADS 64

/* Pairs found by one thread of a threaded build (scratch, grown at builds only). */
typedef struct {
    int32_t *pi, *pj; /* element indices, pi < pj */
    double *R;        /* m, sum of the radii */
    uint8_t *cls;     /* CDEM_CLASS_* base class */
    size_t n, cap;    /* used, capacity */
    int failed;       /* 1: out of memory while growing */
} cdem_pair_buf;

typedef struct {
    /* configuration (set by init) */
    double skin;         /* m, extra list distance beyond contact reach, > 0 */
    double reach_factor; /* pairs interact up to R * reach_factor (1 + max breaking strain) */
    int resort_every;    /* re-sort the state into cell order every this many builds, >= 1 */
    long par_min;        /* builds of at most this many elements enumerate pairs on one
                            thread; the list is the same either way (default CDEM_PAR_MIN,
                            >= 0) */

    /* pair list, struct of arrays, np used of pcap */
    size_t np, pcap;
    int32_t *pi, *pj;  /* element indices, pi < pj */
    double *R;         /* m, sum of the radii */
    uint8_t *cls;      /* CDEM_CLASS_* of the pair */
    uint8_t *hist;     /* CDEM_PAIR_* history flags */
    double *xs;        /* m, accumulated tangential displacement (contact frame) */
    double *pfx, *pfy; /* N, contact force on pi of the last evaluation (pj gets minus) */
    int slot_count;    /* the law's history slots per pair (cdem_neighbour_set_slots), >= 0 */
    double *slots;     /* pair p's at slots[p * slot_count ..] (pcap * slot_count; NULL when
                          slot_count is 0) */

    /* per-element pair slots, in a fixed order: the slots where e is pi are the range
     * istart[e]..istart[e+1]-1 (pairs are enumerated by ascending pi); the slots where e is
     * pj are jslot[jstart[e]..jstart[e+1]-1], ascending */
    int32_t *istart; /* n + 1 */
    int32_t *jstart; /* n + 1 */
    int32_t *jslot;  /* np */

    /* per-element buffers (ncap) */
    size_t n;         /* elements at the last build */
    size_t ncap;      /* capacity of per-element buffers */
    double *x0, *y0;  /* m, positions at the last build */
    int32_t *cell_of; /* cell of each element */
    size_t *perm;     /* re-sort permutation (new index -> old index) */
    size_t *oldmap;   /* index before the build -> index after (SIZE_MAX: removed) */
    void *scratch;    /* permutation scratch, ncap * 8 bytes */

    /* cell grid */
    size_t ccap;                      /* capacity of cell_start */
    int32_t *cell_start;              /* ncells + 1 */
    int32_t *cell_items;              /* element indices sorted by cell (ncap) */
    double *cell_x, *cell_y, *cell_r; /* m: x, y, radius of cell_items[k] at k (ncap; the
                                         vector distance test reads them without gathers) */
    int simd; /* the build's distance test: 0 until the first build (then CDEM_SIMD as the
                 force pass: "scalar", else AVX2 where the CPU has it), 1 scalar, 2 AVX2 */

    /* carried histories */
    size_t ncarry, carrycap;
    cdem_pair_carry *carry;
    double *carry_slots; /* carry[k]'s slots at carry_slots[k * slot_count ..] (NULL when none) */

    /* per-thread pair buffers of a threaded build (thread t enumerates the t-th contiguous
     * element range; the buffers are concatenated in thread order) */
    cdem_pair_buf tbuf[CDEM_NB_MAX_THREADS];

    long n_builds; /* builds so far */
    long n_sorts;  /* re-sorts so far */
} cdem_neighbour;

/* The cell-ordered candidates of a build, for cdem_neighbour_near_avx2. */
typedef struct {
    const double *x, *y, *r; /* cell_x, cell_y, cell_r */
    const int32_t *item;     /* cell_items */
    double reach_factor, skin;
} cdem_neighbour_cells;

/* 1 when this build and CPU have cdem_neighbour_near_avx2. */
int cdem_neighbour_avx2_usable(void);

/* The list build's distance test of element i (at xi, yi, radius ri) against the candidates
 * k0..k1-1 in cell order (neighbour_avx2.c): writes the positions k of those with item > i
 * within reach, ascending, and their R = ri + r, into out_k, out_R (room for k1 - k0);
 * returns how many. The bits and order of the scalar test. Only when usable. */
size_t cdem_neighbour_near_avx2(const cdem_neighbour_cells *c, int32_t i, double xi, double yi,
                                double ri, int32_t k0, int32_t k1, int32_t *out_k, double *out_R);

/* Sets up an empty list. skin > 0 (m); reach_factor >= 1. The pairs have no history slots
 * until cdem_neighbour_set_slots. */
cdem_status cdem_neighbour_init(cdem_neighbour *nb, double skin, double reach_factor,
                                int resort_every, cdem_error *err);

/* Gives every pair `count` history slots (the granular law's, cdem_contact_law slot_count),
 * zero until the law writes them; before the first build or restore only (else
 * CDEM_ERR_INVALID). They are carried as Xs is (rebuilds, removal, re-sorting), set back to 0
 * with it when the pair separates (the force pass, contact.h) and stored in checkpoints. */
cdem_status cdem_neighbour_set_slots(cdem_neighbour *nb, int count, cdem_error *err);
void cdem_neighbour_free(cdem_neighbour *nb);

/* 1 when the list must be rebuilt: the element count changed, or some element moved more
 * than skin/2 since the last build (or there was no build yet). */
int cdem_neighbour_needs_rebuild(const cdem_neighbour *nb, const cdem_state *s);

/* 1 when some element lo..hi-1 (all < the state's n, which must equal the list's n) moved
 * more than skin/2 since the last build (or has a NaN position): the per-element test of
 * cdem_neighbour_needs_rebuild, for callers that split the elements among threads. */
int cdem_neighbour_moved(const cdem_neighbour *nb, const cdem_state *s, size_t lo, size_t hi);

/* The criterion for one element at position (x, y): 1 when it moved more than skin/2 from
 * (x0, y0), its position at the last build, or a coordinate is NaN; lim2 = (skin/2)^2
 * (cdem_neighbour_moved_limit2). Written so that NaN also triggers a rebuild (which then
 * reports it). For loops that test while they move the elements (the force pass's drift). */
static inline int cdem_neighbour_moved_one(double x, double y, double x0, double y0, double lim2) {
    const double dx = x - x0, dy = y - y0;
    return !(dx * dx + dy * dy <= lim2);
}
static inline double cdem_neighbour_moved_limit2(const cdem_neighbour *nb) {
    return 0.25 * nb->skin * nb->skin;
}

/* Rebuilds the list. keep (optional, length s->n): elements with keep[i] == 0 are removed
 * from the state first (histories of the rest kept). resort: 1 forces a re-sort into cell
 * order, 0 lets resort_every decide, -1 never. Fails with CDEM_ERR_NUMERIC naming the
 * element id when a position is not finite. */
cdem_status cdem_neighbour_build(cdem_neighbour *nb, cdem_state *s, const unsigned char *keep,
                                 int resort, cdem_error *err);

/* Checkpoints (checkpoint.h): the whole list under "nb." — pairs in their order (pi, pj, R,
 * cls), the contact histories (hist, xs; with history slots also slot_count and slots, in
 * pair order: a list without slots is stored as it always was), the last pair forces (pfx,
 * pfy), the reference positions of the last build (x0, y0), n, n_builds, n_sorts — so a
 * resumed run rebuilds at the same steps, re-sorts at the same builds and sums forces in the
 * same pair order. The CSR (istart, jstart, jslot) is derived from pi, pj exactly as a build
 * derives it. */
cdem_status cdem_neighbour_snapshot_put(const cdem_neighbour *nb, cdem_snapshot *snap,
                                        cdem_error *err);
/* Restores into nb (initialised with the same skin, reach factor and slot count, else
 * CDEM_ERR_CONFLICT naming the value) for the state s already restored (s->n must equal the
 * stored n). */
cdem_status cdem_neighbour_snapshot_get(cdem_neighbour *nb, const cdem_snapshot *snap,
                                        const cdem_state *s, cdem_error *err);

/* Key of a pair of ids (order-independent). */
static inline uint64_t cdem_pair_key(int32_t a, int32_t b) {
    uint32_t lo = (uint32_t)(a < b ? a : b), hi = (uint32_t)(a < b ? b : a);
    return ((uint64_t)lo << 32) | hi;
}

#endif
