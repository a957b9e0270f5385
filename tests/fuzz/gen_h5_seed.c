/* gen_h5_seed: writes the smallest meaningful cdem file (3 increments of 4 elements, stress in
 * the last, 3 time-series samples) with the h5format writer, as a seed for fuzz_h5 (a real
 * cdem-run output is ~300 kB; this one is a few kB, so mutations reach the structure).
 * Not part of the build; see tests/fuzz/README.md:
 *   clang -std=c17 -D_DEFAULT_SOURCE -Icommon $(pkg-config --cflags hdf5) \
 *     tests/fuzz/gen_h5_seed.c build/libcdem.a $(pkg-config --libs hdf5) -lm -o /tmp/gen
 *   /tmp/gen tests/fuzz/corpus/h5/synthetic.h5 */
#include "h5format.h"

#include <math.h>
#include <stdio.h>

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: gen_h5_seed OUT.h5\n");
        return 2;
    }
    cdem_error err;
    cdem_error_clear(&err);
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "[time]\nruntime = 300\n", "summary", "0.1.0", "gen_h5_seed", 0};
    cdem_h5_writer *w = NULL;
    cdem_state s = {0};
    cdem_status st = cdem_h5_writer_create(argv[1], &meta, &w, &err);
    if (st == CDEM_OK)
        st = cdem_state_init(&s, 8, 0, &err);
    for (int k = 0; k < 4 && st == CDEM_OK; k++)
        st = cdem_state_append(&s, k, 100.0 * k, 50.0, 50.0, 1.0, k % 3, 0u, 0, NULL, &err);
    for (int inc = 0; inc < 3 && st == CDEM_OK; inc++) {
        if (inc == 2)
            st = cdem_state_enable_stress(&s, &err);
        for (size_t i = 0; i < s.n && st == CDEM_OK; i++) {
            s.x[i] += 1.0 * inc;
            if (s.has_stress)
                s.sxx[i] = 1e6, s.syy[i] = 2e6, s.sxy[i] = -1e5;
        }
        cdem_series_sample smp = {.step = 10 * inc, .time = inc, .n_elements = 4, .sea_level = NAN};
        if (st == CDEM_OK)
            st = cdem_h5_writer_append_series(w, &smp, &err);
        cdem_increment_info info = {.number = inc,
                                    .step = 10 * inc,
                                    .time = inc,
                                    .phase = inc ? CDEM_PHASE_DEFORMATION : 0,
                                    .net_displacement = inc,
                                    .sea_level = NAN};
        if (st == CDEM_OK)
            st = cdem_h5_writer_write_increment(w, &info, &s, &err);
    }
    if (st == CDEM_OK)
        st = cdem_h5_writer_set_stop_reason(w, "completed", "gen_h5_seed", &err);
    cdem_status cst = cdem_h5_writer_close(w, &err);
    cdem_state_free(&s);
    if (st != CDEM_OK || cst != CDEM_OK) {
        fprintf(stderr, "gen_h5_seed: %s\n", err.msg);
        return 1;
    }
    return 0;
}
