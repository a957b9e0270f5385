/* neighbour: see neighbour.h. A build is: (1) save the histories of the current pairs by id
 * key, (2) drop removed elements, (3) maybe permute the state into cell order, (4) bin the
 * elements into cells (common/grid.h: counting sort, each cell lists ascending indices), (5) for
 * each element i in index order scan the 3 x 3 cells around it for j > i within reach + skin, (6)
 * restore histories through the index map, (7) build the CSR. Above par_min elements (or
 * pairs), (5) is threaded (contiguous element ranges per thread, buffers appended in thread
 * order), and so are (1), the bounding box and cells of (4) and (6), each in a way that gives
 * the same arrays as one loop; the re-sort, the cell sort and the CSR are serial. So the list
 * is the same for any thread count. */
#include "neighbour.h"

#include "checkpoint.h"
#include "contact.h"
#include "grid.h"
#include "parallel.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static cdem_status grow(void **p, size_t elem, size_t want, cdem_error *err) {
    void *q = realloc(*p, (want ? want : 1) * elem);
    if (!q)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "neighbour list: out of memory for %zu entries",
                         want);
    *p = q;
    return CDEM_OK;
}

static size_t next_cap(size_t cap, size_t want) {
    size_t c = cap ? cap : 64;
    while (c < want)
        c += c / 2 + 1;
    return c;
}

cdem_status cdem_neighbour_init(cdem_neighbour *nb, double skin, double reach_factor,
                                int resort_every, cdem_error *err) {
    memset(nb, 0, sizeof *nb);
    if (!(skin > 0.0) || !isfinite(skin))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "neighbour list: skin = %g m: must be > 0", skin);
    if (!(reach_factor >= 1.0) || !isfinite(reach_factor))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "neighbour list: reach factor = %g: must be >= 1 (1 + breaking strain)",
                         reach_factor);
    nb->skin = skin;
    nb->reach_factor = reach_factor;
    nb->resort_every = resort_every > 0 ? resort_every : 1;
    nb->par_min = CDEM_PAR_MIN;
    return CDEM_OK;
}

cdem_status cdem_neighbour_set_slots(cdem_neighbour *nb, int count, cdem_error *err) {
    if (count < 0 || nb->n_builds != 0 || nb->np != 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "neighbour list: %d history slots a pair: must be >= 0 and set before "
                         "the first build",
                         count);
    nb->slot_count = count;
    if (count > 0 && nb->pcap > 0)
        CDEM_TRY(grow((void **)&nb->slots, sizeof(double) * (size_t)count, nb->pcap, err));
    return CDEM_OK;
}

void cdem_neighbour_free(cdem_neighbour *nb) {
    if (!nb)
        return;
    free(nb->pi);
    free(nb->pj);
    free(nb->R);
    free(nb->cls);
    free(nb->hist);
    free(nb->xs);
    free(nb->slots);
    free(nb->pfx);
    free(nb->pfy);
    free(nb->istart);
    free(nb->jstart);
    free(nb->jslot);
    free(nb->x0);
    free(nb->y0);
    free(nb->cell_of);
    free(nb->perm);
    free(nb->scratch);
    free(nb->cell_start);
    free(nb->cell_items);
    free(nb->cell_x);
    free(nb->cell_y);
    free(nb->cell_r);
    free(nb->carry);
    free(nb->carry_slots);
    free(nb->oldmap);
    for (int t = 0; t < CDEM_NB_MAX_THREADS; t++) {
        free(nb->tbuf[t].pi);
        free(nb->tbuf[t].pj);
        free(nb->tbuf[t].R);
        free(nb->tbuf[t].cls);
    }
    memset(nb, 0, sizeof *nb);
}

int cdem_neighbour_moved(const cdem_neighbour *nb, const cdem_state *s, size_t lo, size_t hi) {
    const double lim2 = cdem_neighbour_moved_limit2(nb);
    const double *restrict x = s->x, *restrict y = s->y;
    const double *restrict x0 = nb->x0, *restrict y0 = nb->y0;
    int out = 0;
    for (size_t i = lo; i < hi; i++)
        out |= cdem_neighbour_moved_one(x[i], y[i], x0[i], y0[i], lim2);
    return out;
}

int cdem_neighbour_needs_rebuild(const cdem_neighbour *nb, const cdem_state *s) {
    if (nb->n_builds == 0 || nb->n != s->n)
        return 1;
    int out = 0;
    const long n = (long)s->n, block = 4096;
#pragma omp parallel for schedule(static) reduction(| : out) if (n > 20000)
    for (long b = 0; b < n; b += block)
        out |= cdem_neighbour_moved(nb, s, (size_t)b, (size_t)(b + block < n ? b + block : n));
    return out;
}

static cdem_status reserve_elements(cdem_neighbour *nb, size_t n, cdem_error *err) {
    if (n <= nb->ncap)
        return CDEM_OK;
    size_t c = next_cap(nb->ncap, n);
    CDEM_TRY(grow((void **)&nb->x0, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->y0, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->cell_of, sizeof(int32_t), c, err));
    CDEM_TRY(grow((void **)&nb->perm, sizeof(size_t), c, err));
    CDEM_TRY(grow((void **)&nb->oldmap, sizeof(size_t), c, err));
    CDEM_TRY(grow((void **)&nb->scratch, 8, c, err));
    CDEM_TRY(grow((void **)&nb->cell_items, sizeof(int32_t), c, err));
    CDEM_TRY(grow((void **)&nb->cell_x, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->cell_y, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->cell_r, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->istart, sizeof(int32_t), c + 1, err));
    CDEM_TRY(grow((void **)&nb->jstart, sizeof(int32_t), c + 1, err));
    nb->ncap = c;
    return CDEM_OK;
}

static cdem_status reserve_pairs(cdem_neighbour *nb, size_t np, cdem_error *err) {
    if (np <= nb->pcap)
        return CDEM_OK;
    size_t c = next_cap(nb->pcap, np);
    CDEM_TRY(grow((void **)&nb->pi, sizeof(int32_t), c, err));
    CDEM_TRY(grow((void **)&nb->pj, sizeof(int32_t), c, err));
    CDEM_TRY(grow((void **)&nb->R, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->cls, sizeof(uint8_t), c, err));
    CDEM_TRY(grow((void **)&nb->hist, sizeof(uint8_t), c, err));
    CDEM_TRY(grow((void **)&nb->xs, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->pfx, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->pfy, sizeof(double), c, err));
    CDEM_TRY(grow((void **)&nb->jslot, sizeof(int32_t), c, err));
    if (nb->slot_count > 0)
        CDEM_TRY(grow((void **)&nb->slots, sizeof(double) * (size_t)nb->slot_count, c, err));
    nb->pcap = c;
    return CDEM_OK;
}

/* Threads for a threaded pass of a build over `items` elements or pairs: 1 at or below
 * par_min, else the current OpenMP count up to CDEM_NB_MAX_THREADS. */
static int build_threads(const cdem_neighbour *nb, size_t items) {
    if ((long)items <= nb->par_min)
        return 1;
    const int nthr = omp_get_max_threads();
    return nthr > CDEM_NB_MAX_THREADS ? CDEM_NB_MAX_THREADS : nthr < 1 ? 1 : nthr;
}

/* Whether pair p has a history to carry (a pair without flags does not touch: its slots, if
 * the law has any, are not a contact's, law.h). */
static int has_history(const cdem_neighbour *nb, size_t p) {
    return nb->hist[p] != 0 || nb->xs[p] != 0.0;
}

/* Pair `from`'s history slots in src to pair `to`'s in dst (m a pair). */
static CDEM_INLINE void copy_slots(size_t m, double *dst, size_t to, const double *src,
                                   size_t from) {
    for (size_t k = 0; k < m; k++)
        dst[to * m + k] = src[from * m + k];
}

/* The histories of the pairs a..b-1 into the carry from entry k on, with their m history
 * slots each. Called with the constant 0 for a law without slots, so that its loop is the
 * one without them. */
static CDEM_INLINE void carry_range(cdem_neighbour *nb, size_t a, size_t b, size_t k, size_t m) {
    for (size_t p = a; p < b; p++) {
        if (!has_history(nb, p))
            continue;
        nb->carry[k].i = nb->pi[p];
        nb->carry[k].j = nb->pj[p];
        nb->carry[k].xs = nb->xs[p];
        nb->carry[k].hist = nb->hist[p];
        copy_slots(m, nb->carry_slots, k, nb->slots, p);
        k++;
    }
}

/* The histories to carry, in slot order: counted and copied by each thread over its own
 * slot range (above par_min pairs), the ranges concatenated in order, so the same list as
 * one loop. */
static cdem_status save_carry(cdem_neighbour *nb, const cdem_state *s, cdem_error *err) {
    nb->ncarry = 0;
    if (nb->n_builds == 0 || nb->n > s->n)
        return CDEM_OK; /* no list yet (or the state was replaced): nothing valid to carry */
    const size_t np = nb->np, m = (size_t)nb->slot_count;
    const int nthr = build_threads(nb, np);
    size_t count[CDEM_NB_MAX_THREADS + 1] = {0}, total = 0;
    int failed = 0;
#pragma omp parallel num_threads(nthr) if (nthr > 1)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const size_t a = np * (size_t)t / (size_t)nt, b = np * (size_t)(t + 1) / (size_t)nt;
        size_t k = 0;
        for (size_t p = a; p < b; p++)
            k += has_history(nb, p);
        count[t + 1] = k;
#pragma omp barrier
#pragma omp single
        {
            for (int q = 0; q < nt; q++)
                count[q + 1] += count[q];
            total = count[nt];
            if (total > nb->carrycap) {
                const size_t c = next_cap(nb->carrycap, total);
                void *q = realloc(nb->carry, c * sizeof(cdem_pair_carry));
                if (q)
                    nb->carry = q;
                void *qs = q && m > 0 ? realloc(nb->carry_slots, c * m * sizeof(double)) : NULL;
                if (qs)
                    nb->carry_slots = qs;
                if (q && (m == 0 || qs))
                    nb->carrycap = c;
                else
                    failed = 1;
            }
        }
        if (!failed) {
            if (m == 0)
                carry_range(nb, a, b, count[t], 0);
            else
                carry_range(nb, a, b, count[t], m);
        }
    }
    if (failed)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "neighbour list: out of memory for %zu entries",
                         total);
    nb->ncarry = total;
    return CDEM_OK;
}

/* Restores carried history k (with its m history slots) into its pair's slot, if the pair is
 * still in the list. */
static CDEM_INLINE void restore_one(cdem_neighbour *nb, long k, size_t m) {
    const cdem_pair_carry *c = &nb->carry[k];
    const size_t a = nb->oldmap[c->i], b = nb->oldmap[c->j];
    if (a == SIZE_MAX || b == SIZE_MAX)
        return; /* an element of the pair was removed */
    const int32_t lo = (int32_t)(a < b ? a : b), hi = (int32_t)(a < b ? b : a);
    for (int32_t p = nb->istart[lo]; p < nb->istart[lo + 1]; p++) {
        if (nb->pj[p] == hi) {
            nb->hist[p] = c->hist;
            nb->xs[p] = c->xs;
            copy_slots(m, nb->slots, (size_t)p, nb->carry_slots, (size_t)k);
            return;
        }
    }
}

/* Restores the saved histories: old indices -> new through oldmap, then the slot of
 * (lo, hi) is found in lo's contiguous pi range. O(pairs). Every carried pair has its own
 * slot: the iterations write disjoint slots. A law without history slots has a loop of its
 * own (restore_one with the constant 0). */
static void restore_carry(cdem_neighbour *nb) {
    const long ncarry = (long)nb->ncarry;
    const size_t m = (size_t)nb->slot_count;
    if (m == 0) {
#pragma omp parallel for schedule(static) if (ncarry > nb->par_min)
        for (long k = 0; k < ncarry; k++)
            restore_one(nb, k, 0);
    } else {
#pragma omp parallel for schedule(static) if (ncarry > nb->par_min)
        for (long k = 0; k < ncarry; k++)
            restore_one(nb, k, m);
    }
}

#define PERMUTE(arr, type)                                                                         \
    do {                                                                                           \
        type *tmp_ = (type *)nb->scratch;                                                          \
        for (size_t k_ = 0; k_ < n; k_++)                                                          \
            tmp_[k_] = (arr)[perm[k_]];                                                            \
        memcpy((arr), tmp_, n * sizeof(type));                                                     \
    } while (0)

static void permute_state(cdem_neighbour *nb, cdem_state *s) {
    const size_t n = s->n;
    const size_t *perm = nb->perm;
    PERMUTE(s->id, int32_t);
    PERMUTE(s->x, double);
    PERMUTE(s->y, double);
    PERMUTE(s->vx, double);
    PERMUTE(s->vy, double);
    PERMUTE(s->fx, double);
    PERMUTE(s->fy, double);
    PERMUTE(s->radius, double);
    PERMUTE(s->mass, double);
    PERMUTE(s->layer, int32_t);
    PERMUTE(s->flags, uint32_t);
    PERMUTE(s->born, int32_t);
    if (s->has_stress) {
        PERMUTE(s->sxx, double);
        PERMUTE(s->syy, double);
        PERMUTE(s->sxy, double);
    }
}

/* Grows one thread's pair buffer (called only by its thread, at build time). */
static int buf_grow(cdem_pair_buf *b, size_t want) {
    const size_t c = next_cap(b->cap, want);
    int32_t *pi = realloc(b->pi, c * sizeof *pi);
    if (pi)
        b->pi = pi;
    int32_t *pj = pi ? realloc(b->pj, c * sizeof *pj) : NULL;
    if (pj)
        b->pj = pj;
    double *R = pj ? realloc(b->R, c * sizeof *R) : NULL;
    if (R)
        b->R = R;
    uint8_t *cls = R ? realloc(b->cls, c * sizeof *cls) : NULL;
    if (!cls)
        return -1;
    b->cls = cls;
    b->cap = c;
    return 0;
}

/* Appends the pair (i, j) of radii sum R and class cls to the list (buf NULL) or to buf,
 * whose count the caller keeps in *bn (enumerate says why). */
static CDEM_INLINE cdem_status add_pair(cdem_neighbour *nb, cdem_pair_buf *buf, size_t *bn,
                                        int32_t i, int32_t j, double R, int cls, cdem_error *err) {
    if (buf) {
        if (*bn == buf->cap && buf_grow(buf, *bn + 1) != 0) {
            buf->n = *bn;
            buf->failed = 1;
            return CDEM_ERR_NOMEM;
        }
        const size_t p = (*bn)++;
        buf->pi[p] = i;
        buf->pj[p] = j;
        buf->R[p] = R;
        buf->cls[p] = (uint8_t)cls;
        return CDEM_OK;
    }
    if (nb->np == nb->pcap)
        CDEM_TRY(reserve_pairs(nb, nb->np + 1, err));
    const size_t p = nb->np++;
    nb->pi[p] = i;
    nb->pj[p] = j;
    nb->R[p] = R;
    nb->cls[p] = (uint8_t)cls;
    nb->hist[p] = 0;
    nb->xs[p] = 0.0;
    nb->pfx[p] = 0.0;
    nb->pfy[p] = 0.0;
    return CDEM_OK;
}

/* enumerate with the vector distance test (cdem_neighbour_near_avx2): the candidates of each
 * row of cells in segments of NEAR_SEGMENT, from the cell-ordered copies; the same pairs in
 * the same order with the same R as the scalar loop. */
#define NEAR_SEGMENT 256
static cdem_status enumerate_vec(cdem_neighbour *nb, const cdem_state *s, const cdem_grid *g,
                                 size_t lo, size_t hi, cdem_pair_buf *buf, cdem_error *err) {
    const double *restrict x = s->x, *restrict y = s->y, *restrict rad = s->radius;
    const uint32_t *restrict fl = s->flags;
    const int32_t *restrict cell_start = nb->cell_start, *restrict cell_items = nb->cell_items;
    const cdem_neighbour_cells cells = {.x = nb->cell_x,
                                        .y = nb->cell_y,
                                        .r = nb->cell_r,
                                        .item = cell_items,
                                        .reach_factor = nb->reach_factor,
                                        .skin = nb->skin};
    const size_t nx = g->nx;
    size_t bn = buf ? buf->n : 0;
    int32_t near_k[NEAR_SEGMENT];
    double near_R[NEAR_SEGMENT];
    for (size_t i = lo; i < hi; i++) {
        if (fl[i] & CDEM_FLAG_FOOTWALL)
            continue;
        const cdem_grid_box b = cdem_grid_around(g, (size_t)nb->cell_of[i]);
        const double xi = x[i], yi = y[i], ri = rad[i];
        const uint32_t fi = fl[i];
        for (size_t yy = b.y_lo; yy <= b.y_hi; yy++) {
            const int32_t k0 = cell_start[yy * nx + b.x_lo], k1 = cell_start[yy * nx + b.x_hi + 1];
            for (int32_t ks = k0; ks < k1; ks += NEAR_SEGMENT) {
                const int32_t ke = k1 - ks > NEAR_SEGMENT ? ks + NEAR_SEGMENT : k1;
                const size_t m = cdem_neighbour_near_avx2(&cells, (int32_t)i, xi, yi, ri, ks, ke,
                                                          near_k, near_R);
                for (size_t q = 0; q < m; q++) {
                    const int32_t j = cell_items[near_k[q]];
                    const int cls = cdem_contact_class(fi, fl[j]);
                    if (cls < 0)
                        continue;
                    CDEM_TRY(add_pair(nb, buf, &bn, (int32_t)i, j, near_R[q], cls, err));
                }
            }
        }
    }
    if (buf)
        buf->n = bn;
    return CDEM_OK;
}

/* Enumerates the pairs (i, j > i) of the elements lo..hi-1 in index order: into the list
 * (buf NULL; serial) or into buf (one thread's share; err unused, buf->failed on NOMEM). The
 * buffer's count is kept in a local and stored once at the end: the threads' buffer
 * structs share cache lines, and a count stored at every pair made each store a transfer
 * between the cores (the threaded enumeration ran 1.4 times slower per thread). */
static cdem_status enumerate(cdem_neighbour *nb, const cdem_state *s, const cdem_grid *g, size_t lo,
                             size_t hi, cdem_pair_buf *buf, cdem_error *err) {
    const double *restrict x = s->x, *restrict y = s->y, *restrict rad = s->radius;
    const uint32_t *restrict fl = s->flags;
    const int32_t *restrict cell_start = nb->cell_start, *restrict cell_items = nb->cell_items;
    const double rf = nb->reach_factor, skin = nb->skin;
    const size_t nx = g->nx;
    size_t bn = buf ? buf->n : 0; /* buf->n, in a register (see above) */
    if (nb->simd == 2)
        return enumerate_vec(nb, s, g, lo, hi, buf, err);
    for (size_t i = lo; i < hi; i++) {
        if (fl[i] & CDEM_FLAG_FOOTWALL)
            continue;
        const cdem_grid_box b = cdem_grid_around(g, (size_t)nb->cell_of[i]);
        const double xi = x[i], yi = y[i], ri = rad[i];
        const uint32_t fi = fl[i];
        for (size_t yy = b.y_lo; yy <= b.y_hi; yy++) {
            /* the cells of one row are contiguous in cell_items */
            const int32_t k0 = cell_start[yy * nx + b.x_lo], k1 = cell_start[yy * nx + b.x_hi + 1];
            for (int32_t k = k0; k < k1; k++) {
                const size_t j = (size_t)cell_items[k];
                if (j <= i)
                    continue;
                const double R = ri + rad[j];
                const double cut = R * rf + skin;
                const double dx = x[j] - xi, dy = y[j] - yi;
                if (dx * dx + dy * dy >= cut * cut)
                    continue;
                const int cls = cdem_contact_class(fi, fl[j]);
                if (cls < 0)
                    continue;
                if (buf) {
                    if (bn == buf->cap && buf_grow(buf, bn + 1) != 0) {
                        buf->n = bn;
                        buf->failed = 1;
                        return CDEM_ERR_NOMEM;
                    }
                    const size_t p = bn++;
                    buf->pi[p] = (int32_t)i;
                    buf->pj[p] = (int32_t)j;
                    buf->R[p] = R;
                    buf->cls[p] = (uint8_t)cls;
                    continue;
                }
                if (nb->np == nb->pcap)
                    CDEM_TRY(reserve_pairs(nb, nb->np + 1, err));
                const size_t p = nb->np++;
                nb->pi[p] = (int32_t)i;
                nb->pj[p] = (int32_t)j;
                nb->R[p] = R;
                nb->cls[p] = (uint8_t)cls;
                nb->hist[p] = 0;
                nb->xs[p] = 0.0;
                nb->pfx[p] = 0.0;
                nb->pfy[p] = 0.0;
            }
        }
    }
    if (buf)
        buf->n = bn;
    return CDEM_OK;
}

/* The CSR of slots per element (neighbour.h), in ascending slot order: counts, running
 * sums, then jslot by a counting sort by pj. (Threaded, with a count row per thread, it was
 * no faster on 2 cores: the passes are bound by memory.) */
static cdem_status build_csr(cdem_neighbour *nb, size_t n, cdem_error *err) {
    const size_t np = nb->np;
    if (np > 0)
        CDEM_TRY(reserve_pairs(nb, np, err));
    int32_t *restrict istart = nb->istart, *restrict jstart = nb->jstart;
    const int32_t *restrict pi = nb->pi, *restrict pj = nb->pj;
    memset(istart, 0, (n + 1) * sizeof(int32_t));
    memset(jstart, 0, (n + 1) * sizeof(int32_t));
    for (size_t p = 0; p < np; p++) {
        istart[pi[p] + 1]++;
        jstart[pj[p] + 1]++;
    }
    for (size_t i = 0; i < n; i++) {
        istart[i + 1] += istart[i];
        jstart[i + 1] += jstart[i];
    }
    int32_t *restrict cursor = (int32_t *)nb->scratch;
    if (n > 0)
        memcpy(cursor, jstart, n * sizeof(int32_t));
    for (size_t p = 0; p < np; p++)
        nb->jslot[cursor[pj[p]]++] = (int32_t)p;
    return CDEM_OK;
}

/* (2) Drops the removed elements (keep[i] == 0; keep NULL: none) from the state; oldmap
 * maps each index before the drop to the index after it (SIZE_MAX: removed). */
static void drop_removed(cdem_neighbour *nb, cdem_state *s, const unsigned char *keep) {
    const size_t n_old = s->n;
    if (keep) {
        cdem_state_compact(s, keep, nb->oldmap);
    } else {
        for (size_t i = 0; i < n_old; i++)
            nb->oldmap[i] = i;
    }
}

/* (4, the cells) The cell grid of the elements into *g and the cell of each element into cell_of:
 * cells of at least the largest reach + skin, so every partner is in the 3 x 3 block.
 * Fails with CDEM_ERR_NUMERIC naming the element when a position is not finite. */
static cdem_status bin_elements(cdem_neighbour *nb, const cdem_state *s, cdem_grid *g,
                                cdem_error *err) {
    const size_t n = s->n;
    /* bounding box, largest radius, finiteness (threaded: minima and maxima do not depend on
     * the order, but for the sign of a zero, which moves no element to another cell) */
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY, rmax = 0.0;
    const double *restrict px = s->x, *restrict py = s->y, *restrict prad = s->radius;
    int bad = 0;
    /* clang-format off */
#pragma omp parallel for schedule(static) if ((long)n > nb->par_min) \
    reduction(min : xmin, ymin) reduction(max : xmax, ymax, rmax) reduction(| : bad)
    /* clang-format on */
    for (long i = 0; i < (long)n; i++) {
        /* plain comparisons (the values are finite here): fmin/fmax are library calls */
        const double xi = px[i], yi = py[i], ri = prad[i];
        bad |= !(isfinite(xi) && isfinite(yi));
        xmin = xi < xmin ? xi : xmin;
        xmax = xi > xmax ? xi : xmax;
        ymin = yi < ymin ? yi : ymin;
        ymax = yi > ymax ? yi : ymax;
        rmax = ri > rmax ? ri : rmax;
    }
    for (size_t i = 0; bad && i < n; i++)
        if (!isfinite(s->x[i]) || !isfinite(s->y[i]))
            return CDEM_FAIL(err, CDEM_ERR_NUMERIC,
                             "element id %d has a non-finite position (x = %g, y = %g): the "
                             "simulation blew up; the time step is probably too large for the "
                             "spring constants and masses",
                             (int)s->id[i], s->x[i], s->y[i]);
    if (n == 0) {
        xmin = xmax = ymin = ymax = 0.0;
    }
    cdem_grid_fit(g, xmin, xmax, ymin, ymax, 2.0 * rmax * nb->reach_factor + nb->skin,
                  4.0 * (double)n + 64.0);
    const size_t ncells = g->nx * g->ny;
    if (2 * ncells + 1 > nb->ccap) {
        size_t c = next_cap(nb->ccap, 2 * ncells + 1);
        CDEM_TRY(grow((void **)&nb->cell_start, sizeof(int32_t), c, err));
        nb->ccap = c;
    }
    int32_t *restrict cell_of = nb->cell_of;
#pragma omp parallel for schedule(static) if ((long)n > nb->par_min)
    for (long i = 0; i < (long)n; i++)
        cell_of[i] = (int32_t)cdem_grid_cell(g, px[i], py[i]);
    return CDEM_OK;
}

/* (3) Permutes the state (n > 1 elements) into cell order, and oldmap (over the n_old
 * indices before the drop) and cell_of with it: a stable counting sort by cell, walls among
 * the free elements of their cells, the cells taken along the grid's short side first:
 * column by column in a model wider than high (row by row in a higher one). The force pass
 * cuts the elements into index ranges, one per thread, so the cut between two chunks then
 * runs across the short side, and the walls of each side belong to its chunk: the fewest
 * pairs across the cut, whose cache lines the two cores must exchange every step
 * (docs/performance.md, "Element order"). New index k holds old index perm[k]. The keys
 * live in scratch, the sorted indices in cell_items (both free here). */
static void resort_by_cell(cdem_neighbour *nb, cdem_state *s, const cdem_grid *g, size_t n_old) {
    const size_t n = s->n, ncells = g->nx * g->ny;
    int32_t *key = (int32_t *)nb->scratch;
    const int columns = g->nx > g->ny;
    for (size_t i = 0; i < n; i++) {
        const size_t c = (size_t)nb->cell_of[i];
        key[i] = (int32_t)(columns ? (c % g->nx) * g->ny + c / g->nx : c);
    }
    cdem_grid_sort(key, n, ncells, nb->cell_start, nb->cell_items);
    size_t *perm = nb->perm;
    for (size_t k = 0; k < n; k++)
        perm[k] = (size_t)nb->cell_items[k];
    permute_state(nb, s);
    {
        /* oldmap follows: the element at new index k came from compacted index perm[k] */
        size_t *inv = (size_t *)nb->scratch;
        for (size_t k = 0; k < n; k++)
            inv[perm[k]] = k;
        for (size_t i = 0; i < n_old; i++)
            if (nb->oldmap[i] != SIZE_MAX)
                nb->oldmap[i] = inv[nb->oldmap[i]];
    }
    {
        /* cell_of follows the permutation */
        int32_t *tmp = (int32_t *)nb->scratch;
        for (size_t k = 0; k < n; k++)
            tmp[k] = nb->cell_of[perm[k]];
        memcpy(nb->cell_of, tmp, n * sizeof(int32_t));
    }
    nb->n_sorts++;
}

/* (4, the lists) Lists each cell's elements (cell_start, cell_items: ascending index, a counting
 * sort by cell), chooses the distance test at the first build, and for the vector test copies the
 * positions and radii into cell order. */
static void list_cells(cdem_neighbour *nb, const cdem_state *s, size_t ncells) {
    const size_t n = s->n;
    cdem_grid_sort(nb->cell_of, n, ncells, nb->cell_start, nb->cell_items);
    if (nb->simd == 0) {
        const char *req = getenv("CDEM_SIMD");
        nb->simd = (req && strcmp(req, "scalar") == 0) || !cdem_neighbour_avx2_usable() ? 1 : 2;
    }
    if (nb->simd == 2) {
        /* the vector test's cell-ordered copies */
        const double *restrict px = s->x, *restrict py = s->y, *restrict prad = s->radius;
        const int32_t *restrict items = nb->cell_items;
        double *restrict cx = nb->cell_x, *restrict cy = nb->cell_y, *restrict cr = nb->cell_r;
#pragma omp parallel for schedule(static) if ((long)n > nb->par_min)
        for (long k = 0; k < (long)n; k++) {
            const int32_t e = items[k];
            cx[k] = px[e];
            cy[k] = py[e];
            cr[k] = prad[e];
        }
    }
}

/* (5) on nthr >= 2 threads (above par_min): thread t takes the t-th contiguous element range into
 * its own buffer; the buffers are then appended in thread order: the same list as the serial loop.
 */
static cdem_status enumerate_threaded(cdem_neighbour *nb, const cdem_state *s, const cdem_grid *g,
                                      int nthr, cdem_error *err) {
    const size_t n = s->n;
#pragma omp parallel num_threads(nthr)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        const size_t lo = n * (size_t)t / (size_t)nt, hi = n * (size_t)(t + 1) / (size_t)nt;
        cdem_pair_buf *b = &nb->tbuf[t];
        b->n = 0;
        b->failed = 0;
        enumerate(nb, s, g, lo, hi, b, NULL);
#pragma omp barrier
#pragma omp single
        {
            size_t total = 0;
            int failed = 0;
            for (int q = 0; q < nt; q++) {
                total += nb->tbuf[q].n;
                failed |= nb->tbuf[q].failed;
            }
            nb->np = failed ? SIZE_MAX : total;
            if (!failed && total > nb->pcap && reserve_pairs(nb, total, NULL) != CDEM_OK)
                nb->np = SIZE_MAX;
        }
        if (nb->np != SIZE_MAX) {
            size_t off = 0;
            for (int q = 0; q < t; q++)
                off += nb->tbuf[q].n;
            const size_t m = b->n;
            if (m > 0) { /* a thread with no pairs may never have allocated its buffer */
                memcpy(nb->pi + off, b->pi, m * sizeof *b->pi);
                memcpy(nb->pj + off, b->pj, m * sizeof *b->pj);
                memcpy(nb->R + off, b->R, m * sizeof *b->R);
                memcpy(nb->cls + off, b->cls, m * sizeof *b->cls);
                memset(nb->hist + off, 0, m * sizeof *nb->hist);
            }
            for (size_t k = 0; k < m; k++) {
                nb->xs[off + k] = 0.0;
                nb->pfx[off + k] = 0.0;
                nb->pfy[off + k] = 0.0;
            }
        }
    }
    if (nb->np == SIZE_MAX) {
        nb->np = 0;
        return CDEM_FAIL(err, CDEM_ERR_NOMEM,
                         "neighbour list: out of memory for the pairs of a threaded build "
                         "(%zu elements)",
                         n);
    }
    return CDEM_OK;
}

/* The phases (1) to (7) of the file's opening note, in order. */
cdem_status cdem_neighbour_build(cdem_neighbour *nb, cdem_state *s, const unsigned char *keep,
                                 int resort, cdem_error *err) {
    CDEM_TRY(save_carry(nb, s, err));
    CDEM_TRY(reserve_elements(nb, s->n + 1, err));
    const size_t n_old = s->n;
    drop_removed(nb, s, keep);
    const size_t n = s->n;
    cdem_grid g;
    CDEM_TRY(bin_elements(nb, s, &g, err));
    int do_sort = resort > 0 || (resort == 0 && nb->n_builds % nb->resort_every == 0);
    if (do_sort && n > 1)
        resort_by_cell(nb, s, &g, n_old);
    list_cells(nb, s, g.nx * g.ny);

    /* enumerate pairs: element i in index order, j > i in the 3 x 3 cells around it */
    nb->np = 0;
    const int nthr = build_threads(nb, n);
    if (nthr < 2)
        CDEM_TRY(enumerate(nb, s, &g, 0, n, NULL, err));
    else
        CDEM_TRY(enumerate_threaded(nb, s, &g, nthr, err));
    CDEM_TRY(build_csr(nb, n, err));
    if (nb->slot_count > 0) /* every pair's slots start at 0; the carried ones are restored */
        memset(nb->slots, 0, nb->np * (size_t)nb->slot_count * sizeof *nb->slots);
    restore_carry(nb);
    memcpy(nb->x0, s->x, n * sizeof(double));
    memcpy(nb->y0, s->y, n * sizeof(double));
    nb->n = n;
    nb->n_builds++;
    return CDEM_OK;
}

/* ---------------------------------------------------------------- checkpoints */

cdem_status cdem_neighbour_snapshot_put(const cdem_neighbour *nb, cdem_snapshot *snap,
                                        cdem_error *err) {
    const char *P = "nb";
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "skin", nb->skin, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "reach_factor", nb->reach_factor, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "resort_every", nb->resort_every, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "np", (int64_t)nb->np, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n", (int64_t)nb->n, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_builds", nb->n_builds, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_sorts", nb->n_sorts, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "pi", CDEM_SNAP_I32, nb->np, nb->pi, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "pj", CDEM_SNAP_I32, nb->np, nb->pj, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "R", CDEM_SNAP_F64, nb->np, nb->R, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "cls", CDEM_SNAP_U8, nb->np, nb->cls, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "hist", CDEM_SNAP_U8, nb->np, nb->hist, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "xs", CDEM_SNAP_F64, nb->np, nb->xs, err));
    if (nb->slot_count > 0) { /* only then: a list without slots is stored as it always was */
        CDEM_TRY(cdem_ckpt_put_i64(snap, P, "slot_count", nb->slot_count, err));
        CDEM_TRY(cdem_ckpt_put_array(snap, P, "slots", CDEM_SNAP_F64,
                                     nb->np * (size_t)nb->slot_count, nb->slots, err));
    }
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "pfx", CDEM_SNAP_F64, nb->np, nb->pfx, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "pfy", CDEM_SNAP_F64, nb->np, nb->pfy, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "x0", CDEM_SNAP_F64, nb->n, nb->x0, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "y0", CDEM_SNAP_F64, nb->n, nb->y0, err));
    return CDEM_OK;
}

cdem_status cdem_neighbour_snapshot_get(cdem_neighbour *nb, const cdem_snapshot *snap,
                                        const cdem_state *s, cdem_error *err) {
    const char *P = "nb";
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "skin", nb->skin, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, P, "reach_factor", nb->reach_factor, err));
    int64_t resort_every = 0, np = 0, n = 0, n_builds = 0, n_sorts = 0;
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "resort_every", 1, INT32_MAX, &resort_every, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "np", 0, INT32_MAX, &np, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "n", 0, INT32_MAX, &n, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "n_builds", 0, INT64_MAX, &n_builds, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "n_sorts", 0, INT64_MAX, &n_sorts, err));
    if ((size_t)n != s->n)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "checkpoint nb.n = %lld elements but the state has %zu (corrupt "
                         "checkpoint)",
                         (long long)n, s->n);
    const size_t P_ = (size_t)np, N_ = (size_t)n;
    /* the law's history slots: stored only by a list that has them */
    int64_t slot_count = 0;
    if (cdem_snapshot_get(snap, "nb.slot_count"))
        CDEM_TRY(cdem_ckpt_get_range(snap, P, "slot_count", 1, INT32_MAX, &slot_count, err));
    if (slot_count != nb->slot_count)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "checkpoint nb.slot_count = %lld history slots a contact but this run's "
                         "contact law has %d: the checkpoint belongs to another law",
                         (long long)slot_count, nb->slot_count);
    const cdem_snapshot_array *slots = NULL;
    const size_t S_ = P_ * (size_t)slot_count;
    if (slot_count > 0)
        CDEM_TRY(cdem_ckpt_get_array(snap, P, "slots", CDEM_SNAP_F64, S_, &slots, err));
    const cdem_snapshot_array *pi, *pj, *R, *cls, *hist, *xs, *pfx, *pfy, *x0, *y0;
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "pi", CDEM_SNAP_I32, P_, &pi, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "pj", CDEM_SNAP_I32, P_, &pj, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "R", CDEM_SNAP_F64, P_, &R, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "cls", CDEM_SNAP_U8, P_, &cls, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "hist", CDEM_SNAP_U8, P_, &hist, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "xs", CDEM_SNAP_F64, P_, &xs, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "pfx", CDEM_SNAP_F64, P_, &pfx, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "pfy", CDEM_SNAP_F64, P_, &pfy, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "x0", CDEM_SNAP_F64, N_, &x0, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "y0", CDEM_SNAP_F64, N_, &y0, err));
    /* pairs must be ordered as a build makes them: ascending pi, pi < pj < n */
    const int32_t *a = pi->data, *b = pj->data;
    for (size_t p = 0; p < P_; p++)
        if (a[p] < 0 || a[p] >= b[p] || (size_t)b[p] >= N_ || (p > 0 && a[p] < a[p - 1]))
            return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                             "checkpoint nb.pi/nb.pj: pair %zu = (%d, %d) is not a valid pair of "
                             "%zu elements in list order (corrupt checkpoint)",
                             p, (int)a[p], (int)b[p], N_);
    CDEM_TRY(reserve_elements(nb, N_ + 1, err));
    CDEM_TRY(reserve_pairs(nb, P_, err));
    if (P_ > 0) {
        memcpy(nb->pi, pi->data, P_ * sizeof *nb->pi);
        memcpy(nb->pj, pj->data, P_ * sizeof *nb->pj);
        memcpy(nb->R, R->data, P_ * sizeof *nb->R);
        memcpy(nb->cls, cls->data, P_ * sizeof *nb->cls);
        memcpy(nb->hist, hist->data, P_ * sizeof *nb->hist);
        memcpy(nb->xs, xs->data, P_ * sizeof *nb->xs);
        if (slots)
            memcpy(nb->slots, slots->data, S_ * sizeof *nb->slots);
        memcpy(nb->pfx, pfx->data, P_ * sizeof *nb->pfx);
        memcpy(nb->pfy, pfy->data, P_ * sizeof *nb->pfy);
    }
    if (N_ > 0) {
        memcpy(nb->x0, x0->data, N_ * sizeof *nb->x0);
        memcpy(nb->y0, y0->data, N_ * sizeof *nb->y0);
    }
    nb->np = P_;
    nb->n = N_;
    nb->resort_every = (int)resort_every;
    nb->n_builds = (long)n_builds;
    nb->n_sorts = (long)n_sorts;
    nb->ncarry = 0;
    /* the CSR exactly as cdem_neighbour_build derives it from pi, pj */
    return build_csr(nb, N_, err);
}
