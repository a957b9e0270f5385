/* Writes tests/data/format_v2_chunk8192.h5: a run file as cdem-c wrote it before the chunk
 * sizes shrank (element chunks of 8192 rows, checkpoint slots "CDEMSNPZ": the blob deflated
 * untransposed; docs/format.md, "Versioning"). Built once against the library of commit
 * d5eb302 (the file is committed; test_format_reads_and_resumes_chunk8192_file reads it):
 *   cc -std=c17 -D_DEFAULT_SOURCE -Icommon $(pkg-config --cflags hdf5) \
 *      tests/data/make_format_v2_chunk8192.c build/libcdem.a $(pkg-config --libs hdf5 zlib gsl) \
 *      -lm -fopenmp -o /tmp/make_v2 && /tmp/make_v2 tests/data/format_v2_chunk8192.h5
 * Content, which the test recomputes: increments 0..3 of 40 elements, element i of increment
 * k at x = 100 i + k / 8, y = 50 + i / 3 + k, radius 10 + i % 4, id 1000 + i, layer 1 + i % 5,
 * flags i % 2, born 0; index rows as test_format.c's make_info (phase 0), no series; a
 * checkpoint after increment 2: one array "state.x" of the 40 x of increment 2. */
#include "h5format.h"
#include "snapshot.h"
#include "state.h"

#include <math.h>
#include <stdio.h>

int main(int argc, char **argv) {
    if (argc != 2)
        return 2;
    cdem_error err;
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, NULL, "chunk8192 fixture", "d5eb302", "cdem-run", 0};
    cdem_h5_writer *w = NULL;
    if (cdem_h5_writer_create(argv[1], &meta, &w, &err) != CDEM_OK)
        return fprintf(stderr, "%s\n", err.msg), 1;
    cdem_h5_writer_set_sync(w, 0);
    for (int k = 0; k < 4; k++) {
        cdem_state s = {0};
        cdem_state_init(&s, 40, 0, &err);
        for (int i = 0; i < 40; i++)
            cdem_state_append(&s, 1000 + i, 100.0 * i + k / 8.0, 50.0 + i / 3.0 + k, 10.0 + i % 4,
                              1.0, 1 + i % 5, (uint32_t)(i % 2), 0, NULL, &err);
        cdem_increment_info in = {0};
        in.number = k;
        in.step = 1000 * (int64_t)k + 7;
        in.time = 0.25 * k + 1e-9;
        in.net_displacement = 5.0 * k + 0.125;
        in.axial_strain = 1e-3 * k;
        in.differential_stress = 2.5e7 + k;
        in.sea_level = k % 2 ? 1234.5 + k : NAN;
        if (cdem_h5_writer_write_increment(w, &in, &s, &err) != CDEM_OK)
            return fprintf(stderr, "%s\n", err.msg), 1;
        if (k == 2) {
            cdem_snapshot *snap = NULL;
            cdem_snapshot_alloc(&snap, &err);
            cdem_snapshot_put(snap, "state.x", CDEM_SNAP_F64, 40, s.x, &err);
            if (cdem_h5_writer_write_checkpoint(w, snap, &err) != CDEM_OK)
                return fprintf(stderr, "%s\n", err.msg), 1;
            cdem_snapshot_free(snap);
        }
        cdem_state_free(&s);
    }
    if (cdem_h5_writer_close(w, &err) != CDEM_OK)
        return fprintf(stderr, "%s\n", err.msg), 1;
    return 0;
}
