/* bench_strain: times the strain kernels against the numpy/scipy script a user would write
 * (bench/strain_numpy.py). Built and run by bench/bench_strain.sh (not part of make test):
 *   1. strain of one increment of a 50,000-element state (250 x 200 lattice, k = 50);
 *   2. cumulative strain over 300 increments of a 10,000-element run (100 x 100 lattice):
 *      300 pair fits plus the running sums (generation of the states is not timed).
 * Prints seconds for OMP_NUM_THREADS 1 and 2 (best of 3) and a checksum (sum of the finite
 * max. shear values) that the Python script reproduces. */
#include "bench_strain_states.h"
#include "strain.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>

static double checksum(const cdem_strain_measures *m, size_t n) {
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        if (isfinite(m[i].max_shear))
            s += m[i].max_shear;
    return s;
}

int main(void) {
    cdem_error err;
    cdem_state ref = {0}, cur = {0};
    bench_packing(&ref, 250, 200);
    cdem_state_copy(&cur, &ref, &err);
    bench_deform(&ref, &cur, 50.0);
    cdem_strain_measures *m = malloc(ref.n * sizeof *m);
    for (int threads = 1; threads <= 2; threads++) {
        omp_set_num_threads(threads);
        double best = 1e30;
        for (int rep = 0; rep < 3; rep++) {
            double t0 = omp_get_wtime();
            if (cdem_strain_compute(&ref, &cur, NULL, 0.0, m, &err) != CDEM_OK) {
                fprintf(stderr, "bench: %s\n", err.msg);
                return 1;
            }
            double t = omp_get_wtime() - t0;
            best = t < best ? t : best;
        }
        printf("single %zu elements threads %d seconds %.4f checksum %.10e\n", ref.n, threads, best,
               checksum(m, ref.n));
    }
    free(m);
    cdem_state_free(&ref);
    cdem_state_free(&cur);

    cdem_state base = {0}, prev = {0}, next = {0};
    bench_packing(&base, 100, 100);
    cdem_state_copy(&prev, &base, &err);
    cdem_state_copy(&next, &base, &err);
    m = malloc(base.n * sizeof *m);
    cdem_strain_measures *out = malloc(base.n * sizeof *out);
    for (int threads = 1; threads <= 2; threads++) {
        omp_set_num_threads(threads);
        double best = 1e30;
        for (int rep = 0; rep < 3; rep++) {
            cdem_strain_cum cum;
            cdem_strain_cum_init(&cum);
            double t = 0.0;
            for (int k = 1; k <= 300; k++) {
                bench_deform(&base, &prev, k - 1);
                bench_deform(&base, &next, k);
                double t0 = omp_get_wtime();
                cdem_strain_compute(&prev, &next, NULL, 0.0, m, &err);
                cdem_strain_cum_add(&cum, &next, m, &err);
                t += omp_get_wtime() - t0;
            }
            cdem_strain_cum_get(&cum, &next, 0, out);
            cdem_strain_cum_free(&cum);
            best = t < best ? t : best;
        }
        printf("cumulative %zu elements 300 increments threads %d seconds %.4f checksum %.10e\n",
               base.n, threads, best, checksum(out, base.n));
    }
    free(m);
    free(out);
    cdem_state_free(&base);
    cdem_state_free(&prev);
    cdem_state_free(&next);
    return 0;
}
