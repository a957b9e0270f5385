/* bench_scale: cost per element and step of the solver core for one assembly size
 * (bench/run_bench.sh prints the scaling table from its lines). Builds the assembly,
 * settles it for `equil` steps (walls still; untimed), makes the touching pairs cohesive,
 * then times `steps` deformation steps of the model's boundary mode (default: planar
 * normal fault moving). Threads: OMP_NUM_THREADS (use OMP_WAIT_POLICY=passive on a shared
 * machine). Usage:
 *   bench_scale width height half_radii equil steps [reps]
 * Prints one "BENCH_SCALE ..." line per timed repetition (the run continues from where the
 * previous repetition stopped, so repetitions measure the same model a little later):
 *   threads, N (all elements), pairs, contacts, builds in the run, seconds (wall clock),
 *   cpu_seconds (process, all threads), ns per element-step (wall and CPU), ns per
 *   contact-step (wall), element-steps/s. */
#include "assembly.h"
#include "bc.h"
#include "integrate.h"
#include "model.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now_s(clockid_t id) {
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int fail(const cdem_error *err) {
    fprintf(stderr, "bench_scale: %s\n", err->msg);
    return 1;
}

int main(int argc, char **argv) {
    if (argc < 6) {
        fprintf(stderr, "usage: bench_scale width height half_radii equil steps [reps]\n");
        return 2;
    }
    cdem_params p;
    cdem_params_defaults(&p);
    p.width = atof(argv[1]);
    p.height = atof(argv[2]);
    p.half_radii = atoi(argv[3]);
    const long equil = atol(argv[4]), nsteps = atol(argv[5]);
    const int reps = argc > 6 ? atoi(argv[6]) : 1;
    cdem_model m;
    cdem_error err;
    cdem_state s;
    cdem_assembly_info info;
    cdem_bc bc;
    cdem_integrator it;
    if (cdem_model_derive(&p, &m, &err) || cdem_state_init(&s, 4096, 0, &err) ||
        cdem_assembly_build(&p, &m, &s, &info, &err) || cdem_bc_init(&bc, &p, &m, &s, &err) ||
        cdem_integrator_init(&it, &p, &m, &err))
        return fail(&err);
    cdem_integrator_enable_escape(&it);
    it.boundary_forces = 0; /* as cdem_run between time-series samples */
    for (long k = 0; k < equil; k++)
        if (cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err))
            return fail(&err);
    cdem_integrator_make_cohesive(&it, &s);
    size_t nrem = 0;
    if (cdem_integrator_begin_deformation(&it, &s, &bc, &nrem, &err))
        return fail(&err);
    long k = 0;
    for (int r = 0; r < reps; r++) {
        const long b0 = it.nb.n_builds;
        const double t0 = now_s(CLOCK_MONOTONIC), c0 = now_s(CLOCK_PROCESS_CPUTIME_ID);
        for (long q = 0; q < nsteps; q++) {
            k++;
            if (cdem_integrator_step(&it, &s, &bc, k, m.displacement_per_step, &err))
                return fail(&err);
        }
        const double t1 = now_s(CLOCK_MONOTONIC), c1 = now_s(CLOCK_PROCESS_CPUTIME_ID);
        long contacts, bonds;
        cdem_integrator_count(&it, &contacts, &bonds);
        const double es = (double)s.n * (double)nsteps;
        printf("BENCH_SCALE threads %d N %zu pairs %zu contacts %ld builds %ld steps %ld seconds "
               "%.4f cpu_seconds %.4f ns_per_el_step %.2f cpu_ns_per_el_step %.2f "
               "ns_per_contact_step %.2f el_steps_per_s %.4g\n",
               omp_get_max_threads(), s.n, it.nb.np, contacts, it.nb.n_builds - b0, nsteps,
               t1 - t0, c1 - c0, 1e9 * (t1 - t0) / es, 1e9 * (c1 - c0) / es,
               1e9 * (t1 - t0) / ((double)contacts * (double)nsteps), es / (t1 - t0));
        fflush(stdout);
    }
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
    return 0;
}
