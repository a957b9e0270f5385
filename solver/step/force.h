/* force: the force pass of a time step, over the pair list: every pair force once into its
 * slot (the contact kernel of contact.h / law_*.h does the physics), the per-element sums,
 * and each element's finish: gravity and the other element loads, the damped second half
 * kick, the total force stored in state fx, fy (boundary elements: the contact force on
 * them), the unstable-motion test. It is its own module, behind the narrow interface below
 * (cdem_force_pass: pair list, state, a cdem_force_step of scalars), so that the hot loops
 * can be changed (vectorised) here without touching the stepper.
 * Determinism: every element sums its pair forces in ascending pair order (a scatter in slot
 * order; threads own element chunks, cross-chunk pairs are subtracted first): bit-identical
 * for any thread count and any cut.
 * State: cdem_force holds only scratch derived from the pair list (the chunk decomposition,
 * the cross pairs, the load balance), never serialised: rebuilt whenever the list or the
 * thread count changes. Nothing allocates in a pass; cdem_force_reserve grows the buffers
 * after each list build. Thread safety: one cdem_force per integrator. */
#ifndef CDEM_FORCE_H
#define CDEM_FORCE_H

#include "cdem_error.h"
#include "contact.h"
#include "neighbour.h"
#include "state.h"

#include <stdatomic.h>

/* Paths: how the pair forces and the element loops of the pass are evaluated. Both give the
 * same bits (force_pairs.h says how); the vector one is faster where the CPU has AVX2. It
 * reads the elements of a pair from a packed copy (x, y, vx, vy of an element in 32 bytes)
 * rather than gathering them, and runs the element loops (drift, finish) in lanes too. */
/* Complete passes each vector path is timed for, when the faster is chosen by measuring. */
#define CDEM_FORCE_MEASURE_PASSES 48

typedef enum {
    CDEM_FORCE_PATH_AUTO = 0, /* not chosen yet: the first need (reserve or pass) calls
                                 cdem_force_path_choose with the environment's CDEM_SIMD */
    CDEM_FORCE_PATH_SCALAR,   /* one pair at a time (any CPU) */
    CDEM_FORCE_PATH_AVX2,     /* four pairs at a time in AVX2 lanes, blocks of pairs evaluated
                                 then scattered */
    CDEM_FORCE_PATH_AVX512,   /* the pairs eight at a time in AVX-512 lanes, the rest as AVX2 */
} cdem_force_path;

/* Largest number of element chunks (threads) of the force pass. */
#define CDEM_MAX_CHUNKS 64

typedef struct {
    /* the decomposition. Chunk c owns the elements chunk_elem[c]..chunk_elem[c+1]-1 and their
     * pi ranges; a cross pair has its pj in a later chunk than its pi; every pair is
     * evaluated by the chunk of its pj, and the chunks are cut by estimated work (pairs by
     * pj, elements) scaled by the shares below. */
    int nchunk;                               /* chunks of the last pass, 1..CDEM_MAX_CHUNKS */
    long chunk_build;                         /* nb.n_builds the chunks were derived for */
    size_t chunk_n;                           /* element count the chunks were derived for */
    int32_t chunk_elem[CDEM_MAX_CHUNKS + 1];  /* first element of each chunk; [nchunk] = n */
    int32_t cross_start[CDEM_MAX_CHUNKS + 1]; /* cross pairs into chunk c: cross[cross_start[c]
                                                 .. cross_start[c+1]-1], ascending slots */
    int32_t *cross;                           /* pair slots of the cross pairs (crosscap) */
    size_t crosscap;                          /* capacity of cross, >= nb.pcap after builds */
    uint32_t *elem_work;                      /* scratch of the cut: each element's work */
    size_t workcap;                           /* capacity of elem_work */
    /* progress of each chunk's cross-pair evaluation in the current threaded pass: every
     * cross pair of chunk c at a slot below cross_done[c].slot is evaluated (atomic; reset to
     * 0 before every pass, raised in steps as the chunk's thread goes through its ascending
     * list, INT32_MAX when done). An earlier chunk meeting a cross pair at slot p waits only
     * until every later chunk is past p. One cache line each: the owner writes while the
     * others read. */
    struct {
        _Atomic int32_t slot;
        char pad[64 - sizeof(int32_t)];
    } cross_done[CDEM_MAX_CHUNKS];
    /* load balance: chunk c is cut to receive chunk_share[c] of the estimated work;
     * chunk_time[c] is the running mean of the seconds its thread spent in the passes since
     * the last cut. At every cut the shares move toward equal times, so a thread on a slower
     * or busier core gets less to do. Any cut gives the same bits (the sums do not depend on
     * it), so the shares only change the speed. */
    int share_n;                         /* nchunk the shares are for (0: none yet) */
    double chunk_share[CDEM_MAX_CHUNKS]; /* fractions of the work, sum 1 */
    double chunk_time[CDEM_MAX_CHUNKS];  /* s per pass, running mean (0: none yet) */
    double *acc;            /* the vector path's per-element contact-force sums, x and y
                               interleaved (acc[2e], acc[2e+1]): one 128-bit add per pair end */
    double *pos4;           /* the vector path's packed elements (force_pairs.h: x, y, vx, vy of
                               element e at pos4[4e]), 32-byte aligned */
    size_t acccap;          /* elements acc and pos4 hold */
    cdem_force_path path;   /* the pass's path (AUTO until the first need; a caller may set
                               any path cdem_force_path_usable accepts) */
    int measure_left;       /* passes left of the measured choice between the AVX2 and the
                               AVX-512 kernels (cdem_force_pass), 0: none */
    int law_scalar_only;    /* 1: the run's law has no vector kernel (cdem_force_law_vectorised),
                               so a vector path evaluates its pairs by the scalar kernel: the
                               two vector paths are not measured (they would time the same
                               scalar loop) and the log says so (cdem_force_path_describe) */
    double measure_time[2]; /* s: their fastest pass so far by the wall clock (AVX2, AVX-512;
                               0: none yet) */
} cdem_force;

/* The loads the element finish adds to the contact-force sum of a free element. */
typedef struct {
    double gravity_x, gravity_y; /* m/s^2: gravity's acceleration (the weight m g) */
    double surface_force;        /* N: in -y on elements flagged CDEM_FLAG_SURFACE */
    double edge_force;           /* N: on elements flagged CDEM_FLAG_BIAXIAL_EDGE, +x left of
                                    edge_x_mid, -x elsewhere */
    double edge_x_mid;           /* m */
} cdem_force_loads;

/* What one pass needs besides the pair list and the state. */
typedef struct {
    const cdem_contact_law *law; /* the material's law; the pass applies equilibrating to a
                                    local copy (cdem_contact_law_phase) */
    int equilibrating;           /* 0/1: the packing phase's law */
    double dt;                   /* s: the tangential increment (0: none, the first pass) */
    double damping;              /* N s/m: the viscous coefficient c of this step */
    int kick;                    /* 1: the damped second half kick of the free elements */
    const double *kick_finish;   /* per element 1 / (m + c dt/2) (the stepper's kick factors)
                                    or NULL: divide */
    cdem_force_loads loads;
    long par_min;      /* passes over fewer pairs and elements run on one thread */
    int check_moved;   /* 1: first test the rebuild criterion (cdem_neighbour_moved) */
    int unstable_test; /* 1: find the lowest index whose element moved more than its radius */
    /* 1: first the half kick and drift of the free elements (v += drift_factor F, x += dt v;
     * drift_factor[i] = (dt/2) / m_i, or NULL: divide), each thread over its own chunks, in
     * the pass's one parallel region: the stepper's drift phase without a region of its own */
    int drift;
    const double *drift_factor;
    /* with drift: the boundary mode's per-element move of this step (solver/modes/bc.h step_move,
     * NULL: none), run by each thread over its chunks before their drift (the two commute:
     * boundary elements and free elements) */
    void (*boundary_move)(const void *ctx, cdem_state *s, long lo, long hi);
    const void *boundary_ctx;
} cdem_force_step;

void cdem_force_free(cdem_force *f);

/* The path for a request ("scalar": the scalar path; "avx512": the AVX-512 pair kernel when
 * this build and the CPU have it; anything else or NULL: AVX2 when this build and the CPU
 * have it, else scalar). CDEM_SIMD in the environment is the request of a pass whose path is
 * AUTO; without one (or "auto"), on a CPU with both vector paths, the pass measures them
 * (cdem_force_pass) and keeps the faster, which the run's log names. */
cdem_force_path cdem_force_path_choose(const char *request);

/* 1 when this build and this CPU run path (SCALAR always; AVX2), else 0. */
int cdem_force_path_usable(cdem_force_path path);

/* "auto", "scalar", "avx2" or "avx512". */
const char *cdem_force_path_name(cdem_force_path path);

/* 1 when the law has a vector pair kernel (its row's AVX2 kernel in laws.def, which the
 * AVX-512 path widens), 0 when the vector paths evaluate its pairs one by one with its scalar
 * kernel (the same bits, not the same speed) or this build has no vector path
 * (force_avx2.c). */
int cdem_force_law_vectorised(cdem_granular_law law);

/* The pair kernel that ran, as the run's log names it: the path's name, and on a vector path
 * with a law that has no vector kernel, which (e.g. "avx2, scalar for law test-scalar-only"):
 * a slower path is never reported as the vector one. */
void cdem_force_path_describe(const cdem_force *f, const char *law, char *buf, size_t cap);

/* Grows the buffers for the pair list nb of n elements (after each list build, outside the
 * step's hot loops). */
cdem_status cdem_force_reserve(cdem_force *f, const cdem_neighbour *nb, size_t n, cdem_error *err);

/* Chunks (threads) wanted for a pass over n elements and the pair list nb. */
int cdem_force_chunks_wanted(const cdem_neighbour *nb, long par_min, long n);

/* The element cut of the last pass (chunk_elem, nchunk + 1 entries) when it is current for nb
 * and n elements and has nchunk > 1 chunks, else NULL: the stepper's drift threads over the
 * same ranges, so each thread moves the elements whose forces it computes next. */
const int32_t *cdem_force_current_cut(const cdem_force *f, const cdem_neighbour *nb, size_t n,
                                      int nchunk);

/* The first half kick and drift of the free elements lo..hi-1 (v += f drift_factor[i], or
 * f (dt/2) / m when drift_factor is NULL; x += dt v), the one definition of the stepper's
 * drift, whether in the force pass's region or in a region of its own (integrate.c). With
 * nb, the rebuild test of every element lo..hi-1 in the same loop: returns 1 when one moved
 * more than half the skin since the last build (else, and without nb, 0). */
int cdem_force_drift(cdem_state *s, double dt, const double *drift_factor, const cdem_neighbour *nb,
                     long lo, long hi);

/* One force pass over the pair list nb (matching the state's element count): the drift
 * (in->drift), pair forces, per-element sums and the element finish, threaded over chunks
 * (one parallel region, and after a list build or a change of thread count a second one
 * before it that lists the cross pairs; each
 * thread evaluates the cross pairs into its chunks, publishing its progress, then runs its
 * chunks, waiting only where it meets a cross pair not yet evaluated).
 * check_moved: if some element moved more than half the skin since the last build (tested
 * per chunk in the same parallel region, while the positions are in the cache of the thread
 * that just drifted them), nothing is computed and 1 is returned: the caller rebuilds and
 * calls again without the test. Else returns 0, and *unstable is the lowest index of an
 * element with |v| dt > r (unstable_test set), or -1. */
int cdem_force_pass(cdem_force *f, cdem_neighbour *nb, cdem_state *s, const cdem_force_step *in,
                    long *unstable);

#endif
