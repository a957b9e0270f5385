/* bench_settling: how long an assembly takes to settle, the measurement behind the summary's
 * equilibration rule (solver/run/estimate.h, docs/performance.md, "Estimates before a run").
 * Runs the equilibration of a model given as -s overrides (no output file) and prints, every
 * 100 s of model time, the free elements' mean downward speed and the criterion of cdem-run's
 * end-of-equilibration warning (warn_if_still_settling, solver/run/run.c): the sinking speed
 * times max(t, 400 s) in average radii. The shortest equilibration without the warning is the
 * first t at which that figure stays below 1.
 *
 *   cc ... -o build/bench_settling bench/bench_settling.c build/libcdemsolver.a build/libcdem.a
 *   build/bench_settling -s assembly.radius_scale=0.5 -s time.equilibration=3000 */
#include "bc.h"
#include "model.h"
#include "params.h"
#include "run.h"
#include "run_ctx.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

int main(int argc, char **argv) {
    cdem_params p;
    cdem_error err;
    cdem_error_clear(&err);
    cdem_params_defaults(&p);
    for (int i = 1; i + 1 < argc; i += 2)
        if (!strcmp(argv[i], "-s") && cdem_params_override(&p, argv[i + 1], &err) != CDEM_OK) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
    if (cdem_run_validate(&p, &err) != CDEM_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    cdem_run_options opt = {.quiet = 1, .log = stderr};
    cdem_run_ctx *r = NULL;
    if (cdem_run_open(&p, &opt, NULL, &r, &err) != CDEM_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    long n_free = 0;
    for (size_t i = 0; i < r->s.n; i++)
        n_free += !(r->s.flags[i] & CDEM_FLAGS_BOUNDARY);
    printf("# %ld free elements, height %g m, average radius %g m (%.1f average diameters "
           "tall), dt %g s, equilibration %ld steps\n",
           n_free, r->m.height_m, r->m.average_radius, r->m.height_m / (2 * r->m.average_radius),
           r->m.dt, r->m.equil_steps);
    printf("# t_s sinking_m_per_s criterion_radii\n");
    const long every = lround(100.0 / r->m.dt);
    cdem_status st = CDEM_OK;
    for (long step = every; step < r->m.equil_steps && st == CDEM_OK; step += every) {
        st = cdem_run_advance(r, step, &err);
        double sum = 0.0;
        for (size_t i = 0; i < r->s.n; i++)
            if (!(r->s.flags[i] & CDEM_FLAGS_BOUNDARY))
                sum += r->s.vy[i];
        const double t = (double)step * r->m.dt, sinking = -sum / (double)n_free;
        printf("%.0f %.4g %.3g\n", t, sinking, sinking * fmax(t, 400.0) / r->m.average_radius);
        fflush(stdout);
    }
    if (st != CDEM_OK)
        fprintf(stderr, "%s\n", err.msg);
    return cdem_run_close(r, st, &err) == CDEM_OK ? 0 : 1;
}
