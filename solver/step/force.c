/* force: see force.h. One pass: the drift (optional), the rebuild test (optional), then the
 * pair loop (chunk_pass)
 * computes each pair force once into its slot and scatters it to its two elements, then the
 * elements are finished (second half kick, loads, instability test). The scalar path does it
 * here; the vector path with the kernels of force_avx2.c (force_pairs.h).
 * Threads: the elements are cut into one chunk per thread, by estimated work and then by
 * measured thread times (make_chunks, update_shares); a pair is evaluated by the chunk of
 * its second element, so a pair whose two elements lie in different chunks (a cross pair)
 * is evaluated first by the later chunk, which publishes its progress; the earlier chunk
 * waits only if it reaches a cross pair not yet evaluated. Each element's sum has the same
 * additions in the same order (ascending pair index) for any cut, so any thread count and
 * any cut give identical bits, the same as the serial scatter. One parallel region and one
 * barrier per pass (the first pass after a list build or a change of thread count also
 * lists the cross pairs, in a region of its own). */
#include "force.h"

#include "force_pairs.h"

#include <omp.h>
#include <sched.h>
#include <stdlib.h>
#include <string.h>

void cdem_force_free(cdem_force *f) {
    if (!f)
        return;
    free(f->cross);
    free(f->elem_work);
    free(f->acc);
    free(f->pos4);
    memset(f, 0, sizeof *f);
}

/* The path of f's passes: chosen at the first need (reserve or pass) from the environment's
 * CDEM_SIMD (force.h), unless a caller set it. */
static cdem_force_path path_of(cdem_force *f) {
    if (f->path == CDEM_FORCE_PATH_AUTO) {
        const char *req = getenv("CDEM_SIMD");
        f->path = cdem_force_path_choose(req);
        /* no request and two vector paths: the first passes measure which is faster here */
        if ((!req || !*req || strcmp(req, "auto") == 0) && f->path == CDEM_FORCE_PATH_AVX2 &&
            !f->law_scalar_only && cdem_force_path_usable(CDEM_FORCE_PATH_AVX512)) {
            f->measure_left = 2 * CDEM_FORCE_MEASURE_PASSES;
            f->measure_time[0] = f->measure_time[1] = 0.0;
        }
    }
    return f->path;
}

/* The vector kernels of a path, or NULL (the scalar path). */
static const cdem_force_kernels *kernels_of(cdem_force_path path) {
    return path == CDEM_FORCE_PATH_AVX2     ? cdem_force_kernels_avx2()
           : path == CDEM_FORCE_PATH_AVX512 ? cdem_force_kernels_avx512()
                                            : NULL;
}

cdem_status cdem_force_reserve(cdem_force *f, const cdem_neighbour *nb, size_t n, cdem_error *err) {
    if (f->crosscap < nb->pcap) {
        const size_t c = nb->pcap;
        int32_t *q = realloc(f->cross, (c ? c : 1) * sizeof *q);
        if (!q)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu cross pairs)", c);
        f->cross = q;
        f->crosscap = c;
    }
    if (f->workcap < n) {
        const size_t c = n + n / 2 + 16;
        uint32_t *w = realloc(f->elem_work, c * sizeof *w);
        if (!w)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu elements)", c);
        f->elem_work = w;
        f->workcap = c;
    }
    /* only the vector paths' buffers: the scalar path's memory stays as it was */
    if (path_of(f) != CDEM_FORCE_PATH_SCALAR && f->acccap < n) {
        const size_t c = n + n / 2 + 16;
        double *a = realloc(f->acc, 2 * c * sizeof *a);
        if (!a)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu elements)", c);
        f->acc = a;
        free(f->pos4);
        f->pos4 = aligned_alloc(32, 4 * c * sizeof *f->pos4); /* a multiple of 32 bytes */
        if (!f->pos4) {
            f->acccap = 0;
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "integrator: out of memory (%zu elements)", c);
        }
        f->acccap = c;
    }
    return CDEM_OK;
}

/* Everything the force pass reads or writes, gathered once per step. */
typedef struct {
    const cdem_contact_law *law;
    double dt;
    cdem_force_elements fin; /* the elements' finish */
    const double *x, *y, *Rp;
    const int32_t *pi, *pj, *istart;
    const uint8_t *cls;
    uint8_t *hist;
    double *xs, *pfx, *pfy, *fx, *fy, *vx, *vy;
    double *slots; /* the law's history slots (law->slot_count a pair), or NULL */
    int stateful;  /* 1: the law has state (coefficients or slots): its own loop (chunk_pass) */
    int nchunk;    /* chunks of this pass */
    const int32_t *chunk_elem, *cross_start, *cross; /* the decomposition (force.h) */
    cdem_force *f;                                   /* cross_done progress slots */
    const cdem_force_kernels *vec;   /* the vector path's kernels (force.h, "Paths"), or NULL */
    int packed;                      /* 1: the pass's drift packed the elements (pairs.pos4) */
    double *acc;                     /* its interleaved sums (cdem_force acc) */
    cdem_force_pairs pairs;          /* the same arrays, for the block evaluation */
    long unstable[CDEM_MAX_CHUNKS];  /* per chunk: lowest unstable element index, or -1 */
    double seconds[CDEM_MAX_CHUNKS]; /* per thread: time in this pass (load balance) */
} force_pass;

/* Pairs the vector path evaluates before scattering them: their slots (about 40 bytes a
 * pair) and most of their elements stay in the L1 cache until the scatter reads them. */
#define PAIR_BLOCK 128

/* How many cross pairs a chunk evaluates between two publications of its progress: small
 * enough that an earlier chunk seldom waits, large enough that the shared line is rarely
 * written. */
#define CROSS_PUBLISH_EVERY 32

static int32_t cross_progress(const force_pass *fp, int d) {
    return atomic_load_explicit(&fp->f->cross_done[d].slot, memory_order_acquire);
}

/* Waits until every chunk after c has evaluated its cross pairs at slots below `slot` (their
 * slots are read by chunk c) and returns the lowest slot below which all of them are done,
 * so that the caller need not look again before it. Usually no wait at all: the later
 * chunks' threads go through their few cross pairs in ascending slot order, ahead of chunk
 * c's scan through all of its pairs. */
static int32_t wait_cross(const force_pass *fp, int c, int32_t slot) {
    int32_t safe = INT32_MAX;
    for (int d = c + 1; d < fp->nchunk; d++) {
        int32_t v = cross_progress(fp, d);
        for (long spins = 0; v < slot; spins++) {
            if (spins > 1000)
                sched_yield(); /* the other thread may be descheduled (shared machine) */
            v = cross_progress(fp, d);
        }
        if (v < safe)
            safe = v;
    }
    return safe;
}

static void publish_cross(const force_pass *fp, int c, int32_t slot) {
    atomic_store_explicit(&fp->f->cross_done[c].slot, slot, memory_order_release);
}

/* Evaluates the cross pairs into chunk c (their slots only; no sums), in ascending slot
 * order, publishing the progress every CROSS_PUBLISH_EVERY pairs; stateful: cdem_force_pair
 * (a constant). */
static CDEM_INLINE void cross_eval_of(const force_pass *fp, int c, int stateful) {
    const double *restrict x = fp->x, *restrict y = fp->y;
    const double *restrict vx = fp->vx, *restrict vy = fp->vy;
    const int32_t *restrict list = fp->cross;
    const int32_t a = fp->cross_start[c], b = fp->cross_start[c + 1];
    for (int32_t k = a; k < b; k++) {
        const long p = list[k];
        const int32_t i = fp->pi[p], j = fp->pj[p];
        cdem_force_pair(fp->law, p, x[j] - x[i], y[j] - y[i], vx[j] - vx[i], vy[j] - vy[i], fp->Rp,
                        fp->cls, fp->hist, fp->xs, fp->slots, fp->pfx, fp->pfy, fp->dt, stateful);
        if ((k - a) % CROSS_PUBLISH_EVERY == CROSS_PUBLISH_EVERY - 1 && k + 1 < b)
            publish_cross(fp, c, list[k + 1]);
    }
    publish_cross(fp, c, INT32_MAX);
}

/* cross_eval_of for a law with state (a function of its own: chunk_pass says why). */
static __attribute__((noinline)) void cross_eval_stateful(const force_pass *fp, int c) {
    cross_eval_of(fp, c, 1);
}

static void cross_eval(const force_pass *fp, int c) {
    if (fp->stateful)
        cross_eval_stateful(fp, c);
    else
        cross_eval_of(fp, c, 0);
}

/* The run loop's guard (integrate.h) over the chunk's elements, while the velocities are in
 * cache: the lowest index whose element moves more than its radius in a step, or -1. */
static CDEM_INLINE long unstable_in(const force_pass *fp, long lo, long hi) {
    if (!fp->fin.radius)
        return -1;
    for (long i = lo; i < hi; i++)
        if (cdem_force_unstable_one(&fp->fin, i, fp->vx, fp->vy))
            return i;
    return -1;
}

/* The force pass over the elements lo..hi-1 and their pi ranges (pairs istart[lo] ..
 * istart[hi]-1), scalar path. Every element's sum is built in ascending pair order, as one
 * scatter loop over all pairs would: fx, fy of the chunk start at zero, the cross pairs from
 * earlier chunks (list[ca..cb-1], ascending, already evaluated) are subtracted first, then
 * the chunk's pairs are evaluated and scattered in order (a pair whose pj lies in a later
 * chunk was evaluated by that chunk's thread and only adds to its pi here). Then the chunk's
 * elements are finished (docs/performance.md, "Choices in the force pass", says why not per
 * element). */
static CDEM_INLINE void chunk_pass_scalar_of(force_pass *fp, int chunk, int stateful) {
    const long lo = fp->chunk_elem[chunk], hi = fp->chunk_elem[chunk + 1];
    const int32_t *restrict list = fp->cross;
    const int32_t ca = fp->cross_start[chunk], cb = fp->cross_start[chunk + 1];
    const cdem_contact_law *restrict law = fp->law;
    const double *restrict x = fp->x, *restrict y = fp->y;
    double *restrict vx = fp->vx, *restrict vy = fp->vy;
    const int32_t *restrict pj = fp->pj, *restrict istart = fp->istart;
    double *restrict fx = fp->fx, *restrict fy = fp->fy;
    double *restrict pfx = fp->pfx, *restrict pfy = fp->pfy;
    const double dt = fp->dt;
    memset(fx + lo, 0, (size_t)(hi - lo) * sizeof *fx);
    memset(fy + lo, 0, (size_t)(hi - lo) * sizeof *fy);
    for (int32_t k = ca; k < cb; k++) {
        const long p = list[k];
        fx[pj[p]] -= pfx[p];
        fy[pj[p]] -= pfy[p];
    }
    const int32_t *restrict pi = fp->pi;
    const long p0 = istart[lo], pe = istart[hi];
    /* cross pairs at slots below `safe` are evaluated (the last chunk has none out) */
    int32_t safe = chunk + 1 >= fp->nchunk ? INT32_MAX : 0;
    for (long p = p0; p < pe; p++) {
        const int32_t i = pi[p], j = pj[p];
        if (j < hi) {
            cdem_force_pair(law, p, x[j] - x[i], y[j] - y[i], vx[j] - vx[i], vy[j] - vy[i], fp->Rp,
                            fp->cls, fp->hist, fp->xs, fp->slots, pfx, pfy, dt, stateful);
            fx[j] -= pfx[p];
            fy[j] -= pfy[p];
            fx[i] += pfx[p];
            fy[i] += pfy[p];
        } else {
            /* a cross pair: evaluated by the chunk of j (not through the restrict pointers) */
            if (p >= safe)
                safe = wait_cross(fp, chunk, (int32_t)p + 1);
            fx[i] += fp->pfx[p];
            fy[i] += fp->pfy[p];
        }
    }
    /* the cross pairs out of this chunk read its velocities: kick only after all of them */
    if (pe > safe)
        wait_cross(fp, chunk, (int32_t)pe);
    for (long i = lo; i < hi; i++)
        cdem_force_finish_one(&fp->fin, i, fx[i], fy[i], vx, vy, fx, fy);
    fp->unstable[chunk] = unstable_in(fp, lo, hi);
}

/* The scalar path's pass of a law without state. */
static void chunk_pass_scalar(force_pass *fp, int chunk) {
    chunk_pass_scalar_of(fp, chunk, 0);
}

/* The pass of a law with state (coefficients or history slots), on every path: the scalar
 * loop with the laws with state (such a law has no vector kernel, law.h), in a function of
 * its own, so that the loops of all the other laws have none of their code. */
static __attribute__((noinline)) void chunk_pass_stateful(force_pass *fp, int chunk) {
    chunk_pass_scalar_of(fp, chunk, 1);
}

/* The scatter of the evaluated pairs b..be-1 into the interleaved sums, in slot order, as
 * chunk_pass_scalar's; cross says whether the range has cross pairs (pj >= hi) at all. */
static CDEM_INLINE int32_t scatter_block(force_pass *fp, int chunk, long b, long be, long hi,
                                         int32_t safe, int cross) {
    if (!cross) {
        fp->vec->scatter(&fp->pairs, b, be, fp->acc);
        return safe;
    }
    const int32_t *restrict pi = fp->pi, *restrict pj = fp->pj;
    double *restrict acc = fp->acc;
    for (long p = b; p < be; p++) {
        const long i = pi[p], j = pj[p];
        if (j < hi) {
            acc[2 * j] -= fp->pfx[p];
            acc[2 * j + 1] -= fp->pfy[p];
        } else if (p >= safe) {
            safe = wait_cross(fp, chunk, (int32_t)p + 1);
        }
        acc[2 * i] += fp->pfx[p];
        acc[2 * i + 1] += fp->pfy[p];
    }
    return safe;
}

/* chunk_pass_scalar's work on a vector path: the sums in the interleaved buffer acc (zeroed,
 * the incoming cross pairs subtracted), the chunk's elements packed (unless the pass's drift
 * did it), then blocks of PAIR_BLOCK pairs evaluated into their slots by the path's kernel
 * and scattered in slot order, then the finish. Each element's sum has the same additions in
 * the same order as on the scalar path. */
static void chunk_pass_vec(force_pass *fp, int chunk) {
    const long lo = fp->chunk_elem[chunk], hi = fp->chunk_elem[chunk + 1];
    const int32_t ca = fp->cross_start[chunk], cb = fp->cross_start[chunk + 1];
    const long p0 = fp->istart[lo], pe = fp->istart[hi];
    double *acc = fp->acc; /* written by scatter_block too: not restrict here */
    memset(acc + 2 * lo, 0, (size_t)(hi - lo) * 2 * sizeof *acc);
    for (int32_t k = ca; k < cb; k++) {
        const long p = fp->cross[k], j = fp->pj[p];
        acc[2 * j] -= fp->pfx[p];
        acc[2 * j + 1] -= fp->pfy[p];
    }
    /* a chunk's own pairs join two of its elements: only its elements need packing */
    if (!fp->packed)
        fp->vec->pack(fp->x, fp->y, fp->vx, fp->vy, lo, hi, (double *)fp->pairs.pos4);
    int32_t safe = chunk + 1 >= fp->nchunk ? INT32_MAX : 0;
    for (long b = p0; b < pe; b += PAIR_BLOCK) {
        const long be = pe - b > PAIR_BLOCK ? b + PAIR_BLOCK : pe;
        const long cross = fp->vec->pairs(&fp->pairs, b, be, (int32_t)hi);
        safe = scatter_block(fp, chunk, b, be, hi, safe, cross > 0);
    }
    if (pe > safe)
        wait_cross(fp, chunk, (int32_t)pe);
    fp->unstable[chunk] = fp->vec->finish(&fp->fin, acc, fp->vx, fp->vy, fp->fx, fp->fy, lo, hi);
}

static void chunk_pass(force_pass *fp, int chunk) {
    if (fp->stateful)
        chunk_pass_stateful(fp, chunk);
    else if (fp->vec)
        chunk_pass_vec(fp, chunk);
    else
        chunk_pass_scalar(fp, chunk);
}

/* Relative costs of the work of a step: a touching pair, a list pair that does not touch, a
 * free element's drift, rebuild test and finish, a boundary element's (measured:
 * docs/performance.md, "Choices in the force pass"); only their ratios matter. */
enum { WORK_TOUCH = 10, WORK_APART = 3, WORK_FREE = 4, WORK_BOUNDARY = 1 };

/* Each element's work in a threaded step, into work[0..n-1], and their total: its drift and
 * finish, and the pairs whose pj it is (each pair is evaluated by the chunk of its pj),
 * touching or not by the flags of the last evaluation (carried over by the build). One pass
 * over the pairs in slot order: sequential reads, and the adds to work stay in the cache
 * (rather than each element's slots by jslot, which reads the flags in scattered order). */
static uint64_t elements_work(const cdem_neighbour *nb, const uint32_t *restrict flags, size_t n,
                              uint32_t *restrict work) {
    for (size_t e = 0; e < n; e++)
        work[e] = (flags[e] & CDEM_FLAGS_BOUNDARY) ? WORK_BOUNDARY : WORK_FREE;
    const int32_t *restrict pj = nb->pj;
    const uint8_t *restrict hist = nb->hist;
    for (size_t p = 0; p < nb->np; p++)
        work[pj[p]] += (hist[p] & CDEM_PAIR_TOUCH) ? WORK_TOUCH : WORK_APART;
    uint64_t total = 0;
    for (size_t e = 0; e < n; e++)
        total += work[e];
    return total;
}

/* The work shares of the next cut: equal for a new chunk count; else each share scaled by
 * the speed its thread showed since the last cut (share / mean time), so that the times
 * even out, smoothed (half way) and kept above a tenth of an equal share. */
static void update_shares(cdem_force *f, int nchunk) {
    if (f->share_n != nchunk) {
        f->share_n = nchunk;
        for (int c = 0; c < nchunk; c++) {
            f->chunk_share[c] = 1.0 / nchunk;
            f->chunk_time[c] = 0.0;
        }
        return;
    }
    double speed[CDEM_MAX_CHUNKS], sum = 0.0;
    for (int c = 0; c < nchunk; c++) {
        if (!(f->chunk_time[c] > 0.0))
            return; /* a chunk without a measurement: keep the shares */
        speed[c] = f->chunk_share[c] / f->chunk_time[c];
        sum += speed[c];
    }
    double total = 0.0;
    for (int c = 0; c < nchunk; c++) {
        double share = 0.5 * (f->chunk_share[c] + speed[c] / sum);
        if (share < 0.1 / nchunk)
            share = 0.1 / nchunk;
        f->chunk_share[c] = share;
        total += share;
    }
    for (int c = 0; c < nchunk; c++) {
        f->chunk_share[c] /= total;
        f->chunk_time[c] = 0.0;
    }
}

/* Splits the elements into nchunk ranges of about equal work (element_work) and lists the
 * cross pairs of each chunk. A pair is evaluated by the chunk of its pj: its own pairs and
 * the cross pairs coming in from earlier chunks. The cut is by estimated work, since elements
 * cost unequally (walls, pairs that touch; docs/performance.md, "Choices in the force
 * pass"). The cut does not change any result (every element sum has the same additions in
 * the same order for any cut). Falls back to one chunk when the buffer is too small (never
 * after a list build: the stepper calls cdem_force_reserve after each). */
static void make_chunks(cdem_force *f, const cdem_neighbour *nb, const uint32_t *flags, size_t n,
                        int nchunk, long par_min) {
    const size_t np = nb->np;
    if (nchunk > CDEM_MAX_CHUNKS)
        nchunk = CDEM_MAX_CHUNKS;
    if (nchunk < 1 || (size_t)nchunk > n || f->crosscap < np || f->workcap < n)
        nchunk = 1;
    f->nchunk = nchunk;
    f->chunk_build = nb->n_builds;
    f->chunk_n = n;
    f->chunk_elem[0] = 0;
    if (nchunk > 1) {
        update_shares(f, nchunk);
        const uint64_t total = elements_work(nb, flags, n, f->elem_work);
        const uint32_t *restrict work = f->elem_work;
        /* chunk c starts at the first element with at least the shares of chunks 0..c-1 of
         * the work before it */
        double cum = 0.0;
        uint64_t want[CDEM_MAX_CHUNKS];
        for (int c = 1; c < nchunk; c++) {
            cum += f->chunk_share[c - 1];
            want[c] = (uint64_t)(cum * (double)total);
        }
        uint64_t before = 0;
        int c = 1;
        for (size_t e = 0; e < n && c < nchunk; e++) {
            while (c < nchunk && before >= want[c])
                f->chunk_elem[c++] = (int32_t)e;
            before += work[e];
        }
        while (c < nchunk)
            f->chunk_elem[c++] = (int32_t)n;
    }
    f->chunk_elem[nchunk] = (int32_t)n;
    for (int c = 0; c <= nchunk; c++)
        f->cross_start[c] = 0;
    if (nchunk == 1)
        return;
    /* the cross pairs by the chunk of pj, ascending slots in each: counted per chunk of pi
     * and chunk of pj, then each chunk's pairs filled from its offsets (threaded over the
     * chunks of pi: the same list as one loop) */
    int32_t count[CDEM_MAX_CHUNKS][CDEM_MAX_CHUNKS];
#pragma omp parallel num_threads(nchunk) if ((long)nb->np > par_min)
    {
        const int t = omp_get_thread_num(), nt = omp_get_num_threads();
        for (int pass = 0; pass < 2; pass++) {
            for (int ci = t; ci < nchunk; ci += nt) {
                int32_t *row = count[ci], cursor[CDEM_MAX_CHUNKS];
                if (pass == 0) {
                    for (int cj = 0; cj < nchunk; cj++)
                        row[cj] = 0;
                } else {
                    for (int cj = 0; cj < nchunk; cj++)
                        cursor[cj] = row[cj];
                }
                const int32_t end = f->chunk_elem[ci + 1];
                for (int32_t p = nb->istart[f->chunk_elem[ci]]; p < nb->istart[end]; p++) {
                    const int32_t j = nb->pj[p];
                    if (j < end)
                        continue;
                    int cj = ci + 1;
                    while (j >= f->chunk_elem[cj + 1])
                        cj++;
                    if (pass == 0)
                        row[cj]++;
                    else
                        f->cross[cursor[cj]++] = p;
                }
            }
            if (pass == 1)
                break;
#pragma omp barrier
#pragma omp single
            {
                /* chunk cj's list starts at cross_start[cj]; chunk ci's pairs into it follow
                 * those of the chunks before ci: count[ci][cj] becomes their first place */
                for (int cj = 0; cj < nchunk; cj++) {
                    int32_t place = f->cross_start[cj];
                    for (int ci = 0; ci < nchunk; ci++) {
                        const int32_t k = count[ci][cj];
                        count[ci][cj] = place;
                        place += k;
                    }
                    f->cross_start[cj + 1] = place;
                }
            }
        }
    }
}

int cdem_force_path_usable(cdem_force_path path) {
    return path == CDEM_FORCE_PATH_SCALAR ||
           ((path == CDEM_FORCE_PATH_AVX2 || path == CDEM_FORCE_PATH_AVX512) && kernels_of(path));
}

cdem_force_path cdem_force_path_choose(const char *request) {
    if (request && strcmp(request, "scalar") == 0)
        return CDEM_FORCE_PATH_SCALAR;
    if (request && strcmp(request, "avx512") == 0 && cdem_force_path_usable(CDEM_FORCE_PATH_AVX512))
        return CDEM_FORCE_PATH_AVX512;
    return cdem_force_path_usable(CDEM_FORCE_PATH_AVX2) ? CDEM_FORCE_PATH_AVX2
                                                        : CDEM_FORCE_PATH_SCALAR;
}

const char *cdem_force_path_name(cdem_force_path path) {
    return path == CDEM_FORCE_PATH_AVX2     ? "avx2"
           : path == CDEM_FORCE_PATH_AVX512 ? "avx512"
           : path == CDEM_FORCE_PATH_SCALAR ? "scalar"
                                            : "auto";
}

void cdem_force_path_describe(const cdem_force *f, const char *law, char *buf, size_t cap) {
    const int vector = f->path == CDEM_FORCE_PATH_AVX2 || f->path == CDEM_FORCE_PATH_AVX512;
    if (vector && f->law_scalar_only)
        snprintf(buf, cap, "%s, scalar for law %s", cdem_force_path_name(f->path), law);
    else
        snprintf(buf, cap, "%s", cdem_force_path_name(f->path));
}

int cdem_force_chunks_wanted(const cdem_neighbour *nb, long par_min, long n) {
    const long np = (long)nb->np;
    const int want = (np > par_min || n > par_min) ? omp_get_max_threads() : 1;
    return want < 1 ? 1 : (want > CDEM_MAX_CHUNKS ? CDEM_MAX_CHUNKS : want);
}

const int32_t *cdem_force_current_cut(const cdem_force *f, const cdem_neighbour *nb, size_t n,
                                      int nchunk) {
    const int current =
        nchunk > 1 && f->nchunk == nchunk && f->chunk_n == n && f->chunk_build == nb->n_builds;
    return current ? f->chunk_elem : NULL;
}

/* The arguments of the drift of the state s (cdem_force_drift_one), with the rebuild test
 * when nb is given, and the packed elements written when pos4 is. */
static cdem_force_drift_args drift_args(cdem_state *s, double dt, const double *drift_factor,
                                        const cdem_neighbour *nb, double *pos4) {
    return (cdem_force_drift_args){.x = s->x,
                                   .y = s->y,
                                   .vx = s->vx,
                                   .vy = s->vy,
                                   .fx = s->fx,
                                   .fy = s->fy,
                                   .mass = s->mass,
                                   .flags = s->flags,
                                   .factor = drift_factor,
                                   .dt = dt,
                                   .x0 = nb ? nb->x0 : NULL,
                                   .y0 = nb ? nb->y0 : NULL,
                                   .lim2 = nb ? cdem_neighbour_moved_limit2(nb) : 0.0,
                                   .pos4 = pos4};
}

/* The drift (force.h), with the rebuild test in the same loop when nb is given, while each
 * position is in a register. */
int cdem_force_drift(cdem_state *s, double dt, const double *drift_factor, const cdem_neighbour *nb,
                     long lo, long hi) {
    const cdem_force_drift_args d = drift_args(s, dt, drift_factor, nb, NULL);
    int moved = 0;
    for (long i = lo; i < hi; i++)
        moved |= cdem_force_drift_one(&d, i);
    return moved;
}

/* The pass's drift of the elements lo..hi-1 (cdem_force_drift), by the vector path's kernel
 * when it has one, which then also packs them for its pairs. */
static int pass_drift(const force_pass *fp, cdem_state *s, const cdem_force_step *in,
                      const cdem_neighbour *nb, long lo, long hi) {
    if (!fp->vec)
        return cdem_force_drift(s, in->dt, in->drift_factor, nb, lo, hi);
    const cdem_force_drift_args d =
        drift_args(s, in->dt, in->drift_factor, nb, (double *)fp->pairs.pos4);
    return fp->vec->drift(&d, lo, hi);
}

/* The pass (force.h) with the vector kernels vec (NULL: the scalar path): the parallel driver
 * of chunk_pass; see the top of this file. */
static int pass_with(cdem_force *f, cdem_neighbour *nb, cdem_state *s, const cdem_force_step *in,
                     long *unstable, const cdem_force_kernels *vec) {
    cdem_contact_law lawc; /* the law of this step, a local copy: provably not aliased by stores */
    cdem_contact_law_phase(in->law, in->equilibrating, &lawc);
    const int kick = in->kick, check_moved = in->check_moved;
    const long n = (long)s->n;
    double *slots = nb->slot_count > 0 ? nb->slots : NULL; /* the law's history slots */
    force_pass fp = {
        .law = &lawc,
        .dt = in->dt,
        .fin = {.kick = kick,
                .hdt = 0.5 * in->dt,
                .c = in->damping,
                .lift_x = 0.0 - in->loads.gravity_x,
                .lift_y = 0.0 - in->loads.gravity_y,
                .surface_force = in->loads.surface_force,
                .edge_force = in->loads.edge_force,
                .edge_x_mid = in->loads.edge_x_mid,
                .mass = s->mass,
                .x = s->x,
                .kick_finish = in->kick_finish,
                .flags = s->flags,
                .radius = in->unstable_test ? s->radius : NULL,
                .dt2 = in->dt * in->dt},
        .x = s->x,
        .y = s->y,
        .Rp = nb->R,
        .pi = nb->pi,
        .pj = nb->pj,
        .istart = nb->istart,
        .cls = nb->cls,
        .hist = nb->hist,
        .xs = nb->xs,
        .slots = slots,
        .stateful = lawc.coefficient_count > 0 || lawc.slot_count > 0,
        .pfx = nb->pfx,
        .pfy = nb->pfy,
        .fx = s->fx,
        .fy = s->fy,
        .vx = s->vx,
        .vy = s->vy,
    };
    /* (a pass before the first cdem_force_reserve for this size takes the scalar path: the
     * same bits) */
    fp.vec = f->acc && f->acccap >= (size_t)n ? vec : NULL;
    fp.packed = fp.vec && in->drift;
    fp.acc = f->acc;
    fp.pairs = (cdem_force_pairs){.law = &lawc,
                                  .dt = in->dt,
                                  .x = s->x,
                                  .y = s->y,
                                  .vx = s->vx,
                                  .vy = s->vy,
                                  .pi = nb->pi,
                                  .pj = nb->pj,
                                  .R = nb->R,
                                  .cls = nb->cls,
                                  .hist = nb->hist,
                                  .xs = nb->xs,
                                  .pfx = nb->pfx,
                                  .pfy = nb->pfy,
                                  .pos4 = f->pos4};
    const int nch = cdem_force_chunks_wanted(nb, in->par_min, n);
    if (f->nchunk != nch || f->chunk_build != nb->n_builds || f->chunk_n != (size_t)n)
        make_chunks(f, nb, s->flags, (size_t)n, nch, in->par_min);
    const int nchunk = f->nchunk;
    fp.nchunk = nchunk;
    fp.chunk_elem = f->chunk_elem;
    fp.cross_start = f->cross_start;
    fp.cross = f->cross;
    fp.f = f;
    if (nchunk == 1) {
        if (in->drift && in->boundary_move)
            in->boundary_move(in->boundary_ctx, s, 0, n);
        if (in->drift ? pass_drift(&fp, s, in, check_moved ? nb : NULL, 0, n)
                      : check_moved && cdem_neighbour_moved(nb, s, 0, (size_t)n))
            return 1;
        chunk_pass(&fp, 0);
    } else {
        for (int c = 0; c < nchunk; c++)
            atomic_store_explicit(&f->cross_done[c].slot, 0, memory_order_relaxed); /* nothing
                                                evaluated yet: reset before every pass */
        int moved = 0;
        for (int c = 0; c < nchunk; c++)
            fp.seconds[c] = -1.0; /* no time: a thread that did not run */
#pragma omp parallel num_threads(nchunk)
        {
            const int t = omp_get_thread_num(), nt = omp_get_num_threads();
            int go = 1;
            /* each thread moves the elements it tests and computes next */
            int mine = 0;
            for (int c = t; c < nchunk; c += nt) {
                const long lo = fp.chunk_elem[c], hi = fp.chunk_elem[c + 1];
                if (in->drift && in->boundary_move)
                    in->boundary_move(in->boundary_ctx, s, lo, hi);
                if (in->drift)
                    mine |= pass_drift(&fp, s, in, check_moved ? nb : NULL, lo, hi);
                else if (check_moved)
                    mine |= cdem_neighbour_moved(nb, s, (size_t)lo, (size_t)hi);
            }
            if (check_moved) {
                if (mine) {
#pragma omp atomic write
                    moved = 1;
                }
#pragma omp barrier
                int any;
#pragma omp atomic read
                any = moved;
                go = !any;
            } else if (in->drift) {
#pragma omp barrier /* every chunk drifted before any thread reads another's positions */
            }
            /* each thread first evaluates the cross pairs into its chunks, then runs them */
            if (go) {
                const double t0 = omp_get_wtime();
                for (int c = t; c < nchunk; c += nt)
                    cross_eval(&fp, c);
                for (int c = t; c < nchunk; c += nt)
                    chunk_pass(&fp, c);
                fp.seconds[t] = omp_get_wtime() - t0; /* for the load balance */
                if (nt != nchunk)
                    fp.seconds[t] = -1.0;
            }
        }
        if (moved)
            return 1;
        /* running means of the chunks' times (one chunk per thread), for the next cut */
        for (int c = 0; c < nchunk; c++) {
            const double sec = fp.seconds[c];
            if (!(sec >= 0.0))
                continue;
            f->chunk_time[c] = f->chunk_time[c] > 0.0 ? 0.9 * f->chunk_time[c] + 0.1 * sec : sec;
        }
    }
    *unstable = -1;
    for (int c = 0; c < nchunk; c++)
        if (fp.unstable[c] >= 0) {
            *unstable = fp.unstable[c]; /* the lowest index: chunks are in order */
            break;
        }
    return 0;
}

/* The pass (force.h). While the path is being measured (path_of), the passes alternate
 * between the AVX2 and the AVX-512 kernels (the same bits) and time themselves by the wall
 * clock; after CDEM_FORCE_MEASURE_PASSES complete passes each, the one with the shorter
 * fastest pass is the path (the fastest rather than the sum: a pass the machine's other work
 * interrupted says nothing of the kernel). */
int cdem_force_pass(cdem_force *f, cdem_neighbour *nb, cdem_state *s, const cdem_force_step *in,
                    long *unstable) {
    const cdem_force_path path = path_of(f);
    if (f->measure_left <= 0)
        return pass_with(f, nb, s, in, unstable, kernels_of(path));
    const int k = f->measure_left & 1;
    const double t0 = omp_get_wtime();
    const int r = pass_with(f, nb, s, in, unstable,
                            kernels_of(k ? CDEM_FORCE_PATH_AVX512 : CDEM_FORCE_PATH_AVX2));
    if (r == 0) {
        const double t = omp_get_wtime() - t0;
        if (f->measure_time[k] == 0.0 || t < f->measure_time[k])
            f->measure_time[k] = t;
        if (--f->measure_left == 0)
            f->path = f->measure_time[1] < f->measure_time[0] ? CDEM_FORCE_PATH_AVX512
                                                              : CDEM_FORCE_PATH_AVX2;
    }
    return r;
}
