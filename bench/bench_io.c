/* bench_io: reading cost of a cdem file (bench/run_bench.sh, analysis path). Opens RUN.h5,
 * loads every increment once (cdem_h5_reader_load_increment, the call every cdem-strain
 * command uses), REPS times, and prints one line with the median time per increment, the
 * elements per increment and the file size per element-increment. Usage:
 *   bench_io RUN.h5 [REPS (default 3)] */
#include "h5format.h"
#include "state.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <time.h>

static double clock_s(clockid_t id) {
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_d(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: bench_io RUN.h5 [REPS]\n");
        return 2;
    }
    int reps = argc > 2 ? atoi(argv[2]) : 3;
    if (reps < 1 || reps > 99)
        reps = 3;
    struct stat st;
    if (stat(argv[1], &st) != 0) {
        fprintf(stderr, "bench_io: %s: cannot stat\n", argv[1]);
        return 1;
    }
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(argv[1], &r, &err)) {
        fprintf(stderr, "bench_io: %s\n", err.msg);
        return 1;
    }
    const size_t ninc = cdem_h5_reader_increment_count(r);
    cdem_state s = {0};
    double wall[99], cpu[99];
    double el_inc = 0.0;
    for (int q = 0; q < reps; q++) {
        el_inc = 0.0;
        const double t0 = clock_s(CLOCK_MONOTONIC), c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
        for (size_t k = 0; k < ninc; k++) {
            cdem_increment_info info;
            if (cdem_h5_reader_load_increment(r, k, &s, &info, &err)) {
                fprintf(stderr, "bench_io: %s\n", err.msg);
                cdem_state_free(&s);
                cdem_h5_reader_close(r);
                return 1;
            }
            el_inc += (double)s.n;
        }
        wall[q] = clock_s(CLOCK_MONOTONIC) - t0;
        cpu[q] = clock_s(CLOCK_PROCESS_CPUTIME_ID) - c0;
    }
    qsort(wall, (size_t)reps, sizeof *wall, cmp_d);
    qsort(cpu, (size_t)reps, sizeof *cpu, cmp_d);
    const double tw = wall[reps / 2], tc = cpu[reps / 2];
    const double mb = (double)st.st_size / 1e6;
    printf("BENCH_IO increments %zu mean_elements %.0f file_MB %.2f bytes_per_element_increment "
           "%.1f load_ms_per_increment %.3f cpu_ms_per_increment %.3f ns_per_element %.1f "
           "whole_file_s %.3f\n",
           ninc, ninc ? el_inc / (double)ninc : 0.0, mb,
           el_inc > 0.0 ? (double)st.st_size / el_inc : 0.0, ninc ? 1e3 * tw / (double)ninc : 0.0,
           ninc ? 1e3 * tc / (double)ninc : 0.0, el_inc > 0.0 ? 1e9 * tw / el_inc : 0.0, tw);
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
    return 0;
}
