/* bench_solver: element-steps per second of the solver core on the default model (10 x 5
 * units, 2121-ish elements, planar normal fault). Builds the assembly, equilibrates for
 * the model's full equilibration (walls still), creates the cohesive contacts, then times
 * a fixed number of deformation steps. Threads: OMP_NUM_THREADS. Usage:
 *   bench_solver [deformation_steps (default 20000)] [equilibration_steps (default: model)]
 *                [width_units (default 10)] [half_radii 0/1 (default 0)]
 * Prints one line: threads, elements, steps, seconds, element-steps/s by the wall clock and
 * per CPU-second (the latter is the fairer figure when other jobs share the cores). */
#include "assembly.h"
#include "bc.h"
#include "integrate.h"
#include "model.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double cpu_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int fail(const cdem_error *err) {
    fprintf(stderr, "bench_solver: %s\n", err->msg);
    return 1;
}

int main(int argc, char **argv) {
    long nsteps = argc > 1 ? atol(argv[1]) : 20000;
    cdem_params p;
    cdem_params_defaults(&p);
    if (argc > 3)
        p.width = atof(argv[3]);
    if (argc > 4)
        p.half_radii = atoi(argv[4]);
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
    long equil = argc > 2 ? atol(argv[2]) : m.equil_steps;
    double t0 = now_s();
    for (long k = 0; k < equil; k++)
        if (cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err))
            return fail(&err);
    double t1 = now_s(), c1 = cpu_s();
    cdem_integrator_make_cohesive(&it, &s);
    for (long k = 1; k <= nsteps; k++)
        if (cdem_integrator_step(&it, &s, &bc, k, m.displacement_per_step, &err))
            return fail(&err);
    double t2 = now_s(), c2 = cpu_s();
    long contacts, bonds;
    cdem_integrator_count(&it, &contacts, &bonds);
    printf("threads %d  elements %zu (internal %ld)  pairs %zu  contacts %ld  rebuilds %ld  "
           "equilibration %ld steps %.2f s (%.3g el-steps/s)  deformation %ld steps %.2f s  "
           "%.3g element-steps/s (wall clock; per CPU-second of all threads: %.3g)\n",
           omp_get_max_threads(), s.n, info.n_internal, it.nb.np, contacts, it.nb.n_builds, equil,
           t1 - t0, (double)s.n * (double)equil / (t1 - t0), nsteps, t2 - t1,
           (double)s.n * (double)nsteps / (t2 - t1), (double)s.n * (double)nsteps / (c2 - c1));
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
    return 0;
}
