/* bench_assembly: times cdem_assembly_build for the paper's assemblies and the largest one
 * (100 x 7.5 units, half radii) and prints counts, area fraction and wall time.
 * Not part of make test. Build and run from the repository root:
 *   make -j2 build/libcdemsolver.a build/libcdem.a
 *   gcc -O2 -std=c17 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -Icommon -Isolver
 * bench/bench_assembly.c \ build/libcdemsolver.a build/libcdem.a -lgsl -lgslcblas -lm -o
 * build/bench_assembly
 *   ./build/bench_assembly [seed]
 */
#include "assembly.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void fill_model(cdem_model *m, double scaling, int half) {
    static const double units[CDEM_NUM_RADII] = {0.05, 0.075, 0.1, 0.125};
    memset(m, 0, sizeof *m);
    for (int c = 0; c < CDEM_NUM_RADII; c++) {
        m->radius[c] = units[c] * scaling * (half ? 0.5 : 1.0);
        m->mass[c] = 2500.0 * M_PI * m->radius[c] * m->radius[c];
    }
    m->max_radius = m->radius[CDEM_NUM_RADII - 1];
}

int main(int argc, char **argv) {
    const struct {
        double w, h, scaling;
        int half;
        long paper;
    } cases[] = {
        {10, 5, 1000, 0, 2121},    {10, 5, 1000, 1, 8342}, {15, 3, 1000, 1, 7600},
        {25, 2.5, 1000, 1, 10520}, {10, 5, 100, 0, 2121},  {100, 7.5, 1000, 0, 0},
        {100, 7.5, 1000, 1, 0},
    };
    long seed = argc > 1 ? atol(argv[1]) : 1;
    printf("%8s %6s %8s %5s %9s %9s %8s %9s %9s %8s %8s\n", "width", "height", "scaling", "half",
           "internal", "paper", "diff%", "walls", "phi", "wall_s", "cpu_s");
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cdem_params p;
        memset(&p, 0, sizeof p);
        p.base_spacing = 2.0;
        p.width = cases[i].w;
        p.height = cases[i].h;
        p.unit_scaling = cases[i].scaling;
        p.half_radii = cases[i].half;
        p.wall_height_multiplier = 1;
        p.seed = seed;
        cdem_model m;
        fill_model(&m, p.unit_scaling, p.half_radii);
        cdem_state s;
        cdem_error err;
        cdem_error_clear(&err);
        cdem_assembly_info info;
        struct timespec t0, t1, c0, c1;
        if (cdem_state_init(&s, 0, 0, &err) != CDEM_OK) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        clock_gettime(CLOCK_MONOTONIC, &t0);
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
        cdem_status st = cdem_assembly_build(&p, &m, &s, &info, &err);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
        if (st != CDEM_OK) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        double sec = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        double cpu = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
        double diff =
            cases[i].paper ? 100.0 * (info.n_internal - cases[i].paper) / cases[i].paper : 0.0;
        printf("%8g %6g %8g %5d %9ld %9ld %8.2f %9ld %9.4f %8.3f %8.3f\n", p.width, p.height,
               p.unit_scaling, p.half_radii, info.n_internal, cases[i].paper, diff, info.n_wall,
               info.area_fraction, sec, cpu);
        cdem_state_free(&s);
    }
    return 0;
}
