/* bench_scale: cost per element and step of the solver core (bench/run_bench.sh prints the
 * scaling table and the long-run check from its lines). Two modes:
 *
 *   bench_scale scale WIDTH HEIGHT HALF SETTLE ELSTEPS REPS "THREADS..."
 *     Builds the assembly (WIDTH x HEIGHT units, HALF = 1 for half radii), settles it for
 *     SETTLE steps (walls still; untimed), makes the touching pairs cohesive, starts the
 *     default boundary mode (planar normal fault) and then, REPS times, runs about ELSTEPS
 *     element-steps of deformation for each thread count in THREADS (e.g. "1 2"), one after
 *     the other in the same process, so that 1 and 2 threads are interleaved and see the
 *     same load and nearly the same model. One "BENCH_SCALE" line per timed run.
 *
 *   bench_scale twins WIDTH HEIGHT HALF SETTLE ELSTEPS REPS
 *     The machine's 2-core ceiling for this work, measured in the same process and minute as
 *     the 2-thread run it bounds: two models (A, B) are built and settled; then, REPS times,
 *     A alone on 1 thread, A and B at once ("twins": each stepped by a thread of its own, on
 *     1 OpenMP thread; they share nothing), A on 2 OpenMP threads, and A alone again. The
 *     ceiling is what the two cores gave the twins, in lone runs: lone/twin_A + lone/twin_B
 *     (lone: the mean of the two lone runs around them); the efficiency is the 2-thread
 *     speed-up over the ceiling (1: the threads lose nothing to sharing one model). One
 *     "BENCH_TWINS" line per repetition. The vCPUs of a shared virtual machine change speed
 *     independently from second to second, so a speed-up alone says little; the efficiency
 *     says how much of what the cores gave the solver's threads used.
 *
 *   bench_scale full WIDTH HEIGHT HALF
 *     The model's whole schedule on the current OMP_NUM_THREADS: equilibration (the
 *     model's equil_steps, walls still), cohesion, deformation to total_steps. Prints one
 *     "BENCH_FULL" line per tenth of the steps with its element-steps per second, so the
 *     first and last tenth show whether the cost degrades over a long run.
 *
 * Figures: N counts all elements (walls included); seconds by the wall clock
 * (CLOCK_MONOTONIC) and the process CPU clock (all threads); ns per element-step; ns per
 * contact-step (contacts = touching pairs at the end of the run). The run loop's
 * instability guard is on, as in cdem-run. OMP_WAIT_POLICY=passive costs a thread wake-up
 * per parallel region (see bench/run_bench.sh). */
#include "assembly.h"
#include "bc.h"
#include "integrate.h"
#include "model.h"

#include <omp.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double clock_s(clockid_t id) {
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int fail(const cdem_error *err) {
    fprintf(stderr, "bench_scale: %s\n", err->msg);
    return 1;
}

typedef struct {
    cdem_params p;
    cdem_model m;
    cdem_state s;
    cdem_assembly_info info;
    cdem_bc bc;
    cdem_integrator it;
    long k; /* deformation steps taken */
} bench;

static cdem_status setup(bench *b, double width, double height, int half, cdem_error *err) {
    memset(b, 0, sizeof *b);
    cdem_params_defaults(&b->p);
    b->p.width = width;
    b->p.height = height;
    b->p.half_radii = half;
    CDEM_TRY(cdem_bc_derive_model(&b->p, &b->m, err));
    CDEM_TRY(cdem_state_init(&b->s, 4096, 0, err));
    CDEM_TRY(cdem_assembly_build(&b->p, &b->m, &b->s, &b->info, err));
    CDEM_TRY(cdem_bc_init(&b->bc, &b->p, &b->m, &b->s, err));
    CDEM_TRY(cdem_integrator_init(&b->it, &b->p, &b->m, err));
    cdem_integrator_enable_escape(&b->it);
    b->it.unstable_guard = 1; /* as cdem_run */
    return CDEM_OK;
}

static cdem_status settle(bench *b, long steps, cdem_error *err) {
    for (long q = 0; q < steps; q++)
        CDEM_TRY(cdem_integrator_step(&b->it, &b->s, NULL, 0, 0.0, err));
    cdem_integrator_make_cohesive(&b->it, &b->s);
    size_t nrem = 0;
    return cdem_integrator_begin_deformation(&b->it, &b->s, &b->bc, &nrem, err);
}

static cdem_status deform(bench *b, long steps, cdem_error *err) {
    for (long q = 0; q < steps; q++) {
        b->k++;
        CDEM_TRY(
            cdem_integrator_step(&b->it, &b->s, &b->bc, b->k, b->m.displacement_per_step, err));
    }
    return CDEM_OK;
}

static void teardown(bench *b) {
    cdem_integrator_free(&b->it);
    cdem_bc_free(&b->bc);
    cdem_state_free(&b->s);
}

/* Deformation steps of a timed run: about elsteps element-steps of an n-element model, at
 * least 20. */
static long timed_steps(double elsteps, size_t n) {
    const long steps = (long)(elsteps / (double)n);
    return steps < 20 ? 20 : steps;
}

static int mode_scale(int argc, char **argv) {
    if (argc < 9) {
        fprintf(stderr, "usage: bench_scale scale WIDTH HEIGHT HALF SETTLE ELSTEPS REPS "
                        "\"THREADS...\"\n");
        return 2;
    }
    bench b;
    cdem_error err;
    if (setup(&b, atof(argv[2]), atof(argv[3]), atoi(argv[4]), &err) ||
        settle(&b, atol(argv[5]), &err))
        return fail(&err);
    const double elsteps = atof(argv[6]);
    const int reps = atoi(argv[7]);
    const long nsteps = timed_steps(elsteps, b.s.n);
    for (int r = 0; r < reps; r++) {
        char list[256];
        snprintf(list, sizeof list, "%s", argv[8]);
        for (char *tok = strtok(list, " ,"); tok; tok = strtok(NULL, " ,")) {
            const int threads = atoi(tok);
            if (threads < 1)
                continue;
            omp_set_num_threads(threads);
            const long b0 = b.it.nb.n_builds;
            const double t0 = clock_s(CLOCK_MONOTONIC), c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
            if (deform(&b, nsteps, &err))
                return fail(&err);
            const double t1 = clock_s(CLOCK_MONOTONIC), c1 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
            long contacts, bonds;
            cdem_integrator_count(&b.it, &contacts, &bonds);
            const double es = (double)b.s.n * (double)nsteps;
            double load = 0.0;
            FILE *f = fopen("/proc/loadavg", "r");
            if (f) {
                if (fscanf(f, "%lf", &load) != 1)
                    load = 0.0;
                fclose(f);
            }
            printf("BENCH_SCALE rep %d threads %d N %zu pairs %zu contacts %ld builds %ld steps "
                   "%ld seconds %.4f cpu_seconds %.4f ns_per_el_step %.2f cpu_ns_per_el_step "
                   "%.2f ns_per_contact_step %.2f el_steps_per_s %.4g load %.2f\n",
                   r, threads, b.s.n, b.it.nb.np, contacts, b.it.nb.n_builds - b0, nsteps, t1 - t0,
                   c1 - c0, 1e9 * (t1 - t0) / es, 1e9 * (c1 - c0) / es,
                   1e9 * (t1 - t0) / ((double)(contacts > 0 ? contacts : 1) * (double)nsteps),
                   es / (t1 - t0), load);
            fflush(stdout);
        }
    }
    teardown(&b);
    return 0;
}

/* One twin's run: `steps` deformation steps of its model on 1 OpenMP thread, timed. */
typedef struct {
    bench *b;
    long steps;
    double seconds;
    cdem_status status;
    cdem_error err;
} twin_run;

static void *twin_main(void *arg) {
    twin_run *t = arg;
    omp_set_num_threads(1); /* this thread's own setting */
    const double t0 = clock_s(CLOCK_MONOTONIC);
    t->status = deform(t->b, t->steps, &t->err);
    t->seconds = clock_s(CLOCK_MONOTONIC) - t0;
    return NULL;
}

static int mode_twins(int argc, char **argv) {
    if (argc < 8) {
        fprintf(stderr, "usage: bench_scale twins WIDTH HEIGHT HALF SETTLE ELSTEPS REPS\n");
        return 2;
    }
    static bench b[2];
    cdem_error err;
    omp_set_num_threads(1);
    for (int k = 0; k < 2; k++)
        if (setup(&b[k], atof(argv[2]), atof(argv[3]), atoi(argv[4]), &err) ||
            settle(&b[k], atol(argv[5]), &err))
            return fail(&err);
    const long nsteps = timed_steps(atof(argv[6]), b[0].s.n);
    const int reps = atoi(argv[7]);
    for (int r = 0; r < reps; r++) {
        twin_run t[2] = {{.b = &b[0], .steps = nsteps}, {.b = &b[1], .steps = nsteps}};
        twin_main(&t[0]);
        const double lone0 = t[0].seconds;
        pthread_t th[2];
        for (int k = 0; k < 2; k++)
            if (pthread_create(&th[k], NULL, twin_main, &t[k]) != 0) {
                fprintf(stderr, "bench_scale: cannot start a thread\n");
                return 1;
            }
        for (int k = 0; k < 2; k++)
            pthread_join(th[k], NULL);
        for (int k = 0; k < 2; k++)
            if (t[k].status != CDEM_OK)
                return fail(&t[k].err);
        const double twin0 = t[0].seconds, twin1 = t[1].seconds;
        omp_set_num_threads(2);
        const double c0 = clock_s(CLOCK_MONOTONIC);
        if (deform(&b[0], nsteps, &err))
            return fail(&err);
        const double two = clock_s(CLOCK_MONOTONIC) - c0;
        twin_main(&t[0]);
        const double lone1 = t[0].seconds, lone = 0.5 * (lone0 + lone1);
        const double ceiling = lone / twin0 + lone / twin1, speedup = lone / two;
        printf("BENCH_TWINS rep %d N %zu steps %ld lone_s %.4f %.4f twins_s %.4f %.4f "
               "two_threads_s %.4f ceiling %.3f speedup %.3f efficiency %.3f\n",
               r, b[0].s.n, nsteps, lone0, lone1, twin0, twin1, two, ceiling, speedup,
               speedup / ceiling);
        fflush(stdout);
    }
    for (int k = 0; k < 2; k++)
        teardown(&b[k]);
    return 0;
}

static int mode_full(int argc, char **argv) {
    if (argc < 5) {
        fprintf(stderr, "usage: bench_scale full WIDTH HEIGHT HALF\n");
        return 2;
    }
    bench b;
    cdem_error err;
    if (setup(&b, atof(argv[2]), atof(argv[3]), atoi(argv[4]), &err))
        return fail(&err);
    const long total = b.m.total_steps, equil = b.m.equil_steps;
    long step = 0;
    for (int tenth = 0; tenth < 10; tenth++) {
        const long end = total * (tenth + 1) / 10;
        const long from = step, b0 = b.it.nb.n_builds, s0 = b.it.nb.n_sorts;
        double es = 0.0;
        const double t0 = clock_s(CLOCK_MONOTONIC), c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
        for (; step < end; step++) {
            es += (double)b.s.n;
            if (step < equil) {
                if (cdem_integrator_step(&b.it, &b.s, NULL, 0, 0.0, &err))
                    return fail(&err);
                if (step + 1 == equil) {
                    cdem_integrator_make_cohesive(&b.it, &b.s);
                    size_t nrem = 0;
                    if (cdem_integrator_begin_deformation(&b.it, &b.s, &b.bc, &nrem, &err))
                        return fail(&err);
                }
            } else if (deform(&b, 1, &err)) {
                return fail(&err);
            }
        }
        const double t1 = clock_s(CLOCK_MONOTONIC), c1 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
        printf("BENCH_FULL tenth %d steps %ld-%ld phase %s N %zu builds %ld sorts %ld seconds "
               "%.4f cpu_seconds %.4f el_steps_per_s %.4g cpu_el_steps_per_s %.4g\n",
               tenth + 1, from, end - 1,
               end <= equil ? "equilibration" : (from >= equil ? "deformation" : "both"), b.s.n,
               b.it.nb.n_builds - b0, b.it.nb.n_sorts - s0, t1 - t0, c1 - c0, es / (t1 - t0),
               es / (c1 - c0));
        fflush(stdout);
    }
    teardown(&b);
    return 0;
}

int main(int argc, char **argv) {
    if (argc > 1 && strcmp(argv[1], "scale") == 0)
        return mode_scale(argc, argv);
    if (argc > 1 && strcmp(argv[1], "twins") == 0)
        return mode_twins(argc, argv);
    if (argc > 1 && strcmp(argv[1], "full") == 0)
        return mode_full(argc, argv);
    fprintf(stderr, "usage: bench_scale scale|twins|full ... (see the comment at the top of "
                    "bench/bench_scale.c)\n");
    return 2;
}
