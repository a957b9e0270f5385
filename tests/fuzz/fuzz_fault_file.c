/* fuzz_fault_file: the irregular-fault vertex reader (solver/modes/fault_file.c). The input is
 * written to a temporary file and read with the first vertex expected at x0 = 1400 m
 * (tolerance 25 m, as tests/test_fault_file.c). Invariants checked on success: at least two
 * finite vertices, x strictly decreasing, y increasing from 0, and the curve queries
 * (x_at, distance) finite. */
#include "fault_file.h"

#include "fuzz_util.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char dir[512], path[600];
    if (fuzz_mkdtemp(dir, sizeof dir) != 0)
        return 0;
    snprintf(path, sizeof path, "%s/fault.txt", dir);
    if (fuzz_write_file(path, data, size) == 0) {
        cdem_fault_polyline pl;
        cdem_error err;
        cdem_error_clear(&err);
        cdem_status st = cdem_fault_file_read(path, 1400.0, 25.0, &pl, &err);
        if (st == CDEM_OK) {
            FUZZ_CHECK(pl.n >= 2);
            FUZZ_CHECK(fabs(pl.x[0] - 1400.0) <= 25.0);
            for (size_t i = 0; i < pl.n; i++) {
                FUZZ_CHECK(isfinite(pl.x[i]) && isfinite(pl.y[i]));
                if (i > 0)
                    FUZZ_CHECK(pl.x[i] < pl.x[i - 1] && pl.y[i] > pl.y[i - 1]);
            }
            const double ys[] = {-100.0, 0.0, 0.5 * pl.y[pl.n - 1], pl.y[pl.n - 1], 1e6};
            for (size_t k = 0; k < sizeof ys / sizeof ys[0]; k++) {
                FUZZ_CHECK(isfinite(cdem_fault_file_x_at(&pl, ys[k])));
                FUZZ_CHECK(isfinite(cdem_fault_file_distance(&pl, 1000.0, ys[k])));
            }
        } else {
            FUZZ_CHECK(err.msg[0] != '\0' && strstr(err.msg, path) != NULL);
            FUZZ_CHECK(pl.n == 0);
        }
        cdem_fault_file_free(&pl);
    }
    fuzz_rmdir(dir);
    return 0;
}
