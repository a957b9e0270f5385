/* bench_machine: what the machine itself gives 2 threads, measured in the same `make bench`
 * run as the solver (bench/run_bench.sh prints it first), so a 2-thread speed-up of the
 * solver can be read against the best any code could get at that moment.
 *
 *   bench_machine
 *
 * Prints one "BENCH_MACHINE" line per probe:
 *   compute  a loop of square roots and divisions on registers (no memory traffic): the
 *            speed-up of 2 threads over 1 when both cores are really available;
 *   triad    a[i] = b[i] + 1.5 c[i] over three arrays of 6 MB and 24 MB in all (the working
 *            sets of the ~35,000- and ~130,000-element models) and 240 MB (main memory):
 *            GB/s on 1 and 2 threads and their ratio. On a virtual machine whose caches and
 *            memory are shared with other guests this ratio moves from run to run (1.0x to
 *            2.0x was seen for 24 MB on the same machine within an hour), and with it the
 *            speed-up of every code that streams its data, the solver's included.
 * Best of 7 (compute: 3) timings each; OMP_NUM_THREADS is ignored (set per probe). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

static double compute_seconds(int threads, double *checksum) {
    double best = INFINITY;
    for (int r = 0; r < 3; r++) {
        double sum = 0.0;
        const double t0 = omp_get_wtime();
#pragma omp parallel for num_threads(threads) schedule(static) reduction(+ : sum)
        for (long i = 0; i < 40000000; i++) {
            const double x = (double)i;
            sum += sqrt(x) / (x + 1.0);
        }
        const double dt = omp_get_wtime() - t0;
        if (dt < best)
            best = dt;
        *checksum += sum;
    }
    return best;
}

static double triad_gbs(long n, int threads, double *a, const double *b, const double *c) {
    double best = INFINITY;
    for (int r = 0; r < 7; r++) {
        const double t0 = omp_get_wtime();
#pragma omp parallel for num_threads(threads) schedule(static)
        for (long i = 0; i < n; i++)
            a[i] = b[i] + 1.5 * c[i];
        const double dt = omp_get_wtime() - t0;
        if (dt < best)
            best = dt;
    }
    return 24.0 * (double)n / best / 1e9;
}

int main(void) {
    double checksum = 0.0;
    const double c1 = compute_seconds(1, &checksum), c2 = compute_seconds(2, &checksum);
    printf("BENCH_MACHINE compute threads1_s %.4f threads2_s %.4f speedup %.2f (checksum %.6g)\n",
           c1, c2, c1 / c2, checksum);
    const long sizes[3] = {250000, 1000000, 10000000};
    for (int k = 0; k < 3; k++) {
        const long n = sizes[k];
        double *a = malloc((size_t)n * sizeof *a), *b = malloc((size_t)n * sizeof *b);
        double *c = malloc((size_t)n * sizeof *c);
        if (!a || !b || !c) {
            fprintf(stderr, "bench_machine: out of memory (%ld doubles)\n", n);
            return 1;
        }
        /* first touch by both threads, as the solver's arrays are */
#pragma omp parallel for num_threads(2) schedule(static)
        for (long i = 0; i < n; i++) {
            a[i] = 0.0;
            b[i] = 1.0;
            c[i] = 2.0;
        }
        const double g1 = triad_gbs(n, 1, a, b, c), g2 = triad_gbs(n, 2, a, b, c);
        printf("BENCH_MACHINE triad MB %.0f threads1_GBs %.1f threads2_GBs %.1f speedup %.2f\n",
               24.0 * (double)n / 1e6, g1, g2, g2 / g1);
        free(a);
        free(b);
        free(c);
    }
    return 0;
}
