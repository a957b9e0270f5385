/* governor: how many of its allowed threads a run uses, chosen from measured step times.
 *
 * Why: when another process holds one of the cores, a step on 2 threads waits at each of
 * its barriers for a thread the kernel has descheduled, and the run gets slower than on one
 * thread: 1.18-1.39x with the passive wait policy, 2.2x with libgomp's spinning default, at
 * 16,700 elements on 2 cores (bench/contended.sh, docs/performance.md). No wait policy or
 * barrier fixes that: the partner is simply not running. The solver's results are
 * bit-identical for every thread count (docs/reliability.md), so the count can change at any
 * step without changing a result. The governor therefore times the run on its allowed N
 * threads and, now and then, a short probe on one thread (or, while on one, on N), and keeps
 * whichever ran faster per step.
 *
 * How: a probe is two back-to-back windows of at least GOVERNOR_WINDOW_S seconds and
 * GOVERNOR_WINDOW_MIN_STEPS steps each, first on the current count, then on the other; the
 * other is kept when its time per step is below GOVERNOR_SWITCH_RATIO times the current's
 * (so noise does not flip the choice). A window times the steps only: the caller times each
 * step while a window is open (cdem_governor_times_steps) and passes its seconds, so the
 * run's own serial work between steps (an increment's or a checkpoint's write and sync, a
 * sample, a deposit) does not count. (When the windows were spans of the clock, a write in
 * the first window made the N threads look slower than the one of the second: on an idle
 * machine a run of 16,700 elements that wrote an increment every 1000 steps switched to one
 * thread at step 3024 and ran 11 % of its steps there.) The first probe comes GOVERNOR_FIRST_S into
 * the run; while the choice stands the interval between probes doubles, up to GOVERNOR_MAX_S; after
 * a change it starts again at GOVERNOR_MIN_S. On an idle 2-core machine a probe costs its one
 * window on one thread, about a third of GOVERNOR_WINDOW_S, so well under 1 % of a run. The
 * clock is read every GOVERNOR_CHECK_EVERY steps, and around each step of a window, never
 * for results.
 *
 * CDEM_THREAD_GOVERNOR=off in the environment keeps the N threads throughout (benchmarks of
 * the threads' scaling). A run on one allowed thread has nothing to choose.
 * Ownership: a plain struct in the run's context; init reads omp_get_max_threads, the
 * governor calls omp_set_num_threads (the calling thread's count for the next regions).
 * Thread safety: call from the thread that runs the steps, outside parallel regions. */
#ifndef CDEM_GOVERNOR_H
#define CDEM_GOVERNOR_H

#define GOVERNOR_WINDOW_S         0.05 /* s, least length of a timing window */
#define GOVERNOR_WINDOW_MIN_STEPS 64   /* least steps of a timing window */
#define GOVERNOR_SWITCH_RATIO     0.95 /* the other count must be 5 % faster per step */
#define GOVERNOR_FIRST_S          0.2  /* s, the first probe */
#define GOVERNOR_MIN_S            1.0  /* s between probes after a change */
#define GOVERNOR_MAX_S            30.0 /* s between probes at most */
#define GOVERNOR_CHECK_EVERY      16   /* steps between clock reads */

/* Why 1 thread can measure faster than N, as the help and the run log say it (one text). */
#define GOVERNOR_WHY_ONE                                                                           \
    "other processes using the cores, or a model too small to gain from threads"

typedef enum {
    CDEM_GOVERNOR_RUN,   /* on the chosen count until the next probe */
    CDEM_GOVERNOR_TIME,  /* timing the chosen count (first window of a probe) */
    CDEM_GOVERNOR_PROBE, /* timing the other count (second window) */
} cdem_governor_phase;

typedef struct {
    int enabled;               /* 0: N threads throughout (N = 1, or switched off) */
    int allowed;               /* N: the thread count the run was given */
    int chosen;                /* the count kept between probes (1 or N) */
    int current;               /* the count in use now */
    cdem_governor_phase phase; /* where the probe cycle is */
    double window_seconds;     /* s, the steps' time in the current window so far */
    long window_steps;         /* steps in the current window so far */
    double per_step_chosen;    /* s per step of the chosen count in the probe's first window */
    double interval;           /* s, the next gap between probes */
    double t_next_probe;       /* s, clock at which the next probe starts */
    long probes;               /* probes made */
    long changes;              /* times the chosen count changed */
    long steps_on_one;         /* steps run on one thread by choice (probes not counted) */
    long step_last;            /* the last step seen (for steps_on_one) */
} cdem_governor;

/* Starts the governor at clock `now` (s, monotonic) and step `step`, with the current
 * omp_get_max_threads() as N; reads CDEM_THREAD_GOVERNOR. */
void cdem_governor_init(cdem_governor *g, double now, long step);

/* After a completed step: may start or end a window and change the thread count for the next
 * steps. `now` (s, monotonic) is read by the caller after every step that
 * cdem_governor_times_steps said to time and every GOVERNOR_CHECK_EVERY steps
 * (cdem_governor_wants_clock; pass a negative value otherwise); `step_seconds` is the time
 * of that timed step's stepping alone (negative for a step not timed). Returns 1 when the
 * chosen count changed. */
int cdem_governor_after_step(cdem_governor *g, long step, double now, double step_seconds);

/* Gives the calling thread back the N threads it had at init (a later run in the same
 * process starts from them). */
void cdem_governor_finish(cdem_governor *g);

/* 1 when the caller should time the next step (a window is open): read the clock just
 * before and just after the stepping, without the run's writes. */
static inline int cdem_governor_times_steps(const cdem_governor *g) {
    return g->enabled && g->phase != CDEM_GOVERNOR_RUN;
}

/* 1 when the clock should be read after this step (every GOVERNOR_CHECK_EVERY steps). */
static inline int cdem_governor_wants_clock(const cdem_governor *g, long step) {
    return g->enabled && step % GOVERNOR_CHECK_EVERY == 0;
}

#endif
