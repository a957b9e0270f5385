/* The thread governor (solver/run/governor.c) on a simulated clock: a step takes t_n seconds on
 * the N allowed threads and t_1 on one (the clock advances by the time of the count in use,
 * read every GOVERNOR_CHECK_EVERY steps and around the steps of a window, as the run loop
 * does; optionally a write between steps advances it further).
 *   - busy cores (t_1 < t_n): after the first probe the run goes on one thread and stays
 *     there but for its probes of N, which back off;
 *   - idle cores (t_1 > t_n): it stays on N, and its probes of one thread cost under 1 % of
 *     a minute-long run;
 *   - noise within the 5 % margin does not change the choice;
 *   - the run's writes between steps (increments, checkpoints) do not count: an idle run
 *     that writes often keeps its N threads;
 *   - the cores becoming busy in mid-run, then idle again, are followed both ways;
 *   - CDEM_THREAD_GOVERNOR=off, or one allowed thread, keeps the count;
 *   - finish gives the calling thread its N threads back. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "governor.h"

#include <omp.h>
#include <stdlib.h>

typedef struct {
    double now;       /* s, the simulated clock */
    long write_every; /* steps between writes, 0: none */
    double write_s;   /* s, a write's time (between steps, not part of one) */
    long step;        /* the last completed step */
    long on_one;      /* steps run on one thread (probes included) */
    long changes;     /* after_step returned 1 */
    long first_one;   /* the first step run on one thread by choice, or -1 */
} sim;

/* Runs steps until the clock reaches t_end: each step takes t_n (N threads) or t_1 (one). */
static void run_until(cdem_governor *g, sim *s, double t_end, double t_n, double t_1) {
    while (s->now < t_end) {
        const int one = omp_get_max_threads() == 1;
        const int timed = cdem_governor_times_steps(g);
        const double before = s->now;
        s->now += one ? t_1 : t_n;
        s->on_one += one;
        s->step++;
        const double clock = timed || cdem_governor_wants_clock(g, s->step) ? s->now : -1.0;
        const int changed =
            cdem_governor_after_step(g, s->step, clock, timed ? s->now - before : -1.0);
        if (s->write_every > 0 && s->step % s->write_every == 0)
            s->now += s->write_s; /* after the step, as run.c writes its increments */
        if (changed) {
            s->changes++;
            if (g->chosen == 1 && s->first_one < 0)
                s->first_one = s->step;
        }
    }
}

static void start(cdem_governor *g, sim *s, int n) {
    omp_set_num_threads(n);
    *s = (sim){.first_one = -1};
    cdem_governor_init(g, 0.0, 0);
}

static void test_governor_busy_cores_go_to_one_thread(void **st) {
    (void)st;
    cdem_governor g;
    sim s;
    start(&g, &s, 2);
    assert_true(g.enabled);
    assert_int_equal(g.allowed, 2);
    /* 2 threads 1.5x slower than one (a competitor holds a core): 1 ms vs 0.67 ms a step */
    run_until(&g, &s, 60.0, 1.0e-3, 0.667e-3);
    assert_int_equal(g.chosen, 1);
    assert_int_equal(omp_get_max_threads() == 1 || g.phase == CDEM_GOVERNOR_PROBE, 1);
    /* it changed once, soon after the first probe (0.2 s in, two 0.05 s windows) */
    assert_int_equal(g.changes, 1);
    assert_true(s.first_one > 0 && s.first_one * 1.0e-3 < 0.5);
    /* and spent nearly the whole minute on one thread: its probes of 2 back off to 30 s */
    assert_true((double)s.on_one / (double)s.step > 0.97);
    assert_true(g.probes >= 5 && g.probes < 15);
    cdem_governor_finish(&g);
    assert_int_equal(omp_get_max_threads(), 2);
}

static void test_governor_idle_cores_keep_the_threads(void **st) {
    (void)st;
    cdem_governor g;
    sim s;
    start(&g, &s, 2);
    /* idle: 2 threads 1.6x faster */
    run_until(&g, &s, 60.0, 0.625e-3, 1.0e-3);
    assert_int_equal(g.chosen, 2);
    assert_int_equal(g.changes, 0);
    assert_int_equal(g.steps_on_one, 0);
    /* the probes of one thread: under 1 % of the run's time */
    assert_true((double)s.on_one * 1.0e-3 < 0.01 * 60.0);
    /* noise: one thread 3 % faster is within the margin, so 2 stay */
    start(&g, &s, 2);
    run_until(&g, &s, 20.0, 1.0e-3, 0.97e-3);
    assert_int_equal(g.changes, 0);
    assert_int_equal(g.chosen, 2);
    cdem_governor_finish(&g);
}

/* A minute from the start on N = 2 threads, with a write of 40 ms (an increment with its
 * sync) after every 100th step. */
static void minute_with_writes(cdem_governor *g, sim *s, double t_n, double t_1) {
    start(g, s, 2);
    s->write_every = 100;
    s->write_s = 0.04;
    run_until(g, s, 60.0, t_n, t_1);
}

static void test_governor_writes_do_not_count(void **st) {
    (void)st;
    cdem_governor g;
    sim s;
    /* idle, 2 threads 1.6x faster: most windows hold a write. Timed by the clock's span (the
     * governor of 65e799e, whose windows ended at the clock reads: 64 or 96 steps), a window
     * on N threads with a write read 1.04-1.25 ms a step against one thread's 1 ms, and in
     * this minute the run changed its count 6 times. */
    minute_with_writes(&g, &s, 0.625e-3, 1.0e-3);
    assert_int_equal(g.changes, 0);
    assert_int_equal(g.chosen, 2);
    assert_int_equal(g.steps_on_one, 0);
    assert_true(g.probes >= 5);
    /* and busy cores are still found with the writes: one thread 1.5x faster */
    minute_with_writes(&g, &s, 1.0e-3, 0.667e-3);
    assert_int_equal(g.chosen, 1);
    assert_int_equal(g.changes, 1);
    cdem_governor_finish(&g);
}

static void test_governor_follows_the_load_both_ways(void **st) {
    (void)st;
    cdem_governor g;
    sim s;
    start(&g, &s, 2);
    run_until(&g, &s, 100.0, 0.6e-3, 1.0e-3); /* idle */
    assert_int_equal(g.chosen, 2);
    run_until(&g, &s, 200.0, 2.0e-3, 1.0e-3); /* busy: within a probe interval (<= 30 s) */
    assert_int_equal(g.chosen, 1);
    assert_int_equal(g.changes, 1);
    run_until(&g, &s, 300.0, 0.6e-3, 1.0e-3); /* idle again: back to 2 */
    assert_int_equal(g.chosen, 2);
    assert_int_equal(g.changes, 2);
    cdem_governor_finish(&g);
    assert_int_equal(omp_get_max_threads(), 2);
}

static void test_governor_off_or_one_thread(void **st) {
    (void)st;
    cdem_governor g;
    sim s;
    setenv("CDEM_THREAD_GOVERNOR", "off", 1);
    start(&g, &s, 2);
    assert_false(g.enabled);
    run_until(&g, &s, 10.0, 2.0e-3, 1.0e-3);
    assert_int_equal(s.on_one, 0);
    assert_int_equal(omp_get_max_threads(), 2);
    unsetenv("CDEM_THREAD_GOVERNOR");
    start(&g, &s, 1);
    assert_false(g.enabled);
    run_until(&g, &s, 1.0, 2.0e-3, 1.0e-3);
    assert_int_equal(g.changes, 0);
    cdem_governor_finish(&g);
    assert_int_equal(omp_get_max_threads(), 1);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_governor_busy_cores_go_to_one_thread),
        cmocka_unit_test(test_governor_idle_cores_keep_the_threads),
        cmocka_unit_test(test_governor_writes_do_not_count),
        cmocka_unit_test(test_governor_follows_the_load_both_ways),
        cmocka_unit_test(test_governor_off_or_one_thread),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
