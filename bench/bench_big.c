/* bench_big: the cost of every phase of a run per element, from 10^4 to 10^6 elements (issue
 * 33: "the cost of every phase per element stays flat"). For one model (the default model's
 * parameters at WIDTH x HEIGHT units and RADIUS_SCALE times the default radii):
 *
 *   bench_big WIDTH HEIGHT RADIUS_SCALE STEPS OUTDIR CDEM_STRAIN
 *
 *  - build: the assembly (cdem_assembly_build), timed;
 *  - step: STEPS time steps (the first half of equilibration, then, after cohesion and the
 *    start of the planar fault, the other half of deformation), alternating blocks of 1 and
 *    2 OpenMP threads, timed per block: ns per element-step on each;
 *  - write: three increments (the assembly, the end of the equilibration steps, the end)
 *    written with the run file's writer (cdem_h5_writer_*, syncs off as with --no-fsync),
 *    timed, and the file's bytes per element and increment;
 *  - analyse: `cdem-strain compute FILE --increment last --quantity total-max-shear` and
 *    `cdem-strain render FILE --increment last --color total-max-shear`, each a process of
 *    its own, timed, with its peak resident memory (wait4);
 *  - memory: this process's peak resident size after the steps, per element.
 * One "BENCH_BIG" line with every figure. bench/run_bench.sh (part "big") runs it at about
 * 10^4, 2.5 x 10^5 and 10^6 elements; docs/performance.md, "Scale", records it. */
#include "assembly.h"
#include "bc.h"
#include "h5format.h"
#include "integrate.h"
#include "model.h"
#include "run.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int fail(const cdem_error *err) {
    fprintf(stderr, "bench_big: %s\n", err->msg);
    return 1;
}

/* Runs argv as a child process; its wall time (s) and peak resident size (bytes). 0 or -1. */
static int run_child(char *const argv[], double *seconds, double *rss) {
    const double t0 = now();
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        if (!freopen("/dev/null", "w", stdout))
            _exit(126);
        execv(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return -1;
    *seconds = now() - t0;
    *rss = (double)ru.ru_maxrss * 1024.0;
    return 0;
}

/* Steps block by block, alternating 1 and 2 threads; adds each block's seconds and
 * element-steps to t[threads - 1], es[threads - 1]. */
static cdem_status steps(cdem_integrator *it, cdem_state *s, cdem_bc *bc, long *k, long n,
                         double du, double t[2], double es[2], cdem_error *err) {
    const long block = n < 20 ? n : n / 10;
    for (long done = 0, b = 0; done < n; b++) {
        const int threads = (int)(b % 2) + 1;
        const long m = n - done < block ? n - done : block;
        omp_set_num_threads(threads);
        const double t0 = now();
        for (long q = 0; q < m; q++) {
            if (bc)
                ++*k;
            CDEM_TRY(cdem_integrator_step(it, s, bc, bc ? *k : 0, bc ? du : 0.0, err));
        }
        t[threads - 1] += now() - t0;
        es[threads - 1] += (double)s->n * (double)m;
        done += m;
    }
    return CDEM_OK;
}

int main(int argc, char **argv) {
    if (argc < 7) {
        fprintf(stderr,
                "usage: bench_big WIDTH HEIGHT RADIUS_SCALE STEPS OUTDIR CDEM_STRAIN (see the "
                "comment at the top of bench/bench_big.c)\n");
        return 2;
    }
    cdem_params p;
    cdem_params_defaults(&p);
    p.width = atof(argv[1]);
    p.height = atof(argv[2]);
    p.radius_scale = atof(argv[3]);
    const long nsteps = atol(argv[4]);
    const char *dir = argv[5], *strain = argv[6];
    cdem_error err;
    cdem_model m;
    cdem_state s;
    cdem_assembly_info info;
    cdem_bc bc;
    cdem_integrator it;
    memset(&s, 0, sizeof s);
    memset(&bc, 0, sizeof bc);
    if (cdem_run_validate(&p, &err) != CDEM_OK || cdem_run_check_memory(&p, &err) != CDEM_OK ||
        cdem_bc_derive_model(&p, &m, &err) ||
        cdem_state_init(&s, 4096, 0, &err))
        return fail(&err);
    double t0 = now();
    if (cdem_assembly_build(&p, &m, &s, &info, &err))
        return fail(&err);
    const double build_s = now() - t0;
    if (cdem_bc_init(&bc, &p, &m, &s, &err) || cdem_integrator_init(&it, &p, &m, &err))
        return fail(&err);
    cdem_integrator_enable_escape(&it);
    it.unstable_guard = 1;
    char path[1200];
    snprintf(path, sizeof path, "%s/big.h5", dir);
    unlink(path);
    cdem_run_meta meta = {&p, NULL, "bench_big", "bench", "cdem-run", 4};
    cdem_h5_writer *w = NULL;
    double write_s = 0.0;
    if (cdem_h5_writer_create(path, &meta, &w, &err))
        return fail(&err);
    cdem_h5_writer_set_sync(w, 0);
    cdem_increment_info in = {0};
    in.sea_level = 0.0 / 0.0;
    t0 = now();
    if (cdem_integrator_prime(&it, &s, &err) || cdem_h5_writer_write_increment(w, &in, &s, &err))
        return fail(&err);
    write_s += now() - t0;
    double t[2] = {0, 0}, es[2] = {0, 0};
    long k = 0;
    if (steps(&it, &s, NULL, &k, nsteps / 2, 0.0, t, es, &err))
        return fail(&err);
    in.number = 1;
    in.step = nsteps / 2;
    in.time = (double)in.step * m.dt;
    t0 = now();
    if (cdem_h5_writer_write_increment(w, &in, &s, &err))
        return fail(&err);
    write_s += now() - t0;
    cdem_integrator_make_cohesive(&it, &s);
    size_t nrem = 0;
    if (cdem_integrator_begin_deformation(&it, &s, &bc, &nrem, &err) ||
        steps(&it, &s, &bc, &k, nsteps - nsteps / 2, m.displacement_per_step, t, es, &err))
        return fail(&err);
    in.number = 2;
    in.step = nsteps;
    in.time = (double)in.step * m.dt;
    in.phase = CDEM_PHASE_DEFORMATION;
    in.net_displacement = cdem_bc_net_displacement(&bc);
    t0 = now();
    if (cdem_h5_writer_write_increment(w, &in, &s, &err) ||
        cdem_h5_writer_set_stop_reason(w, "completed", "bench_big", &err) ||
        cdem_h5_writer_close(w, &err))
        return fail(&err);
    write_s += now() - t0;
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    const double rss = (double)ru.ru_maxrss * 1024.0;
    struct stat sb;
    const double file_bytes = stat(path, &sb) == 0 ? (double)sb.st_size : 0.0;
    char csv[1300], png[1300];
    snprintf(csv, sizeof csv, "%s/big.csv", dir);
    snprintf(png, sizeof png, "%s/big.png", dir);
    char *compute[] = {(char *)strain, "compute", path, "--increment", "last", "--quantity",
                       "total-max-shear", "-o", csv, NULL};
    char *render[] = {(char *)strain, "render", path, "--increment", "last", "--color",
                      "total-max-shear", "-o", png, NULL};
    double compute_s = 0, compute_rss = 0, render_s = 0, render_rss = 0;
    if (run_child(compute, &compute_s, &compute_rss) || run_child(render, &render_s, &render_rss)) {
        fprintf(stderr, "bench_big: %s compute or render failed on %s\n", strain, path);
        return 1;
    }
    const double n = (double)s.n;
    printf("BENCH_BIG N %zu build_s %.3f build_us_per_el %.3f ns_per_el_step_1t %.2f "
           "ns_per_el_step_2t %.2f write_s %.3f write_us_per_el_incr %.3f file_bytes_per_el_incr "
           "%.2f compute_s %.3f compute_us_per_el %.3f render_s %.3f render_us_per_el %.3f "
           "rss_bytes_per_el %.0f compute_rss_bytes_per_el %.0f render_rss_bytes_per_el %.0f\n",
           s.n, build_s, 1e6 * build_s / n, 1e9 * t[0] / es[0], 1e9 * t[1] / es[1], write_s,
           1e6 * write_s / (3.0 * n), file_bytes / (3.0 * n), compute_s, 1e6 * compute_s / n,
           render_s, 1e6 * render_s / n, rss / n, compute_rss / n, render_rss / n);
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
    return 0;
}
