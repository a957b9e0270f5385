/* fuzz_h5: the HDF5 element-state reader (common/h5/h5_reader*.c and h5_checkpoint.c, reader
 * API only). The input is written to a temporary file, which is opened and read the way
 * cdem-strain and cdem-run --resume do: every increment's info, find_increment for each spec form,
 * every increment loaded, the time series, the parameter record, the newest checkpoint, a refresh
 * and the stored texts. Invariants checked: loaded states hold the element count their info
 * announces; failures carry a message. Nobody holds the file's lock, so a file marked as
 * being written is read as a complete one, like a killed run's (no SWMR retries: a damaged
 * one once hung the reader). HDF5 itself is not instrumented, so coverage guidance comes
 * from our reader only. */
#include "h5format.h"

#include "fuzz_util.h"

/* HDF5 1.10.8 loses metadata-cache blocks (allocated through its H5FL_ / H5MM_ allocators)
 * when it fails to load a corrupt object header; that memory is HDF5's, not reachable from
 * any handle of ours, and cannot be freed by the caller (docs/reliability.md, "Bad input").
 * These sanitizer hooks (used only in sanitized builds) suppress exactly those allocations;
 * the full unwinder is needed to see the allocator's name in the stack. Our own leaks are
 * still reported: our code never allocates through H5FL_ or H5MM_. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) {
    return "leak:H5FL_\nleak:H5MM_\nleak:libfontconfig\n";
}
const char *__asan_default_options(void);
const char *__asan_default_options(void) {
    return "fast_unwind_on_malloc=0";
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    char dir[512], path[600];
    if (fuzz_mkdtemp(dir, sizeof dir) != 0)
        return 0;
    snprintf(path, sizeof path, "%s/run.h5", dir);
    if (fuzz_write_file(path, data, size) != 0) {
        fuzz_rmdir(dir);
        return 0;
    }
    cdem_error err;
    cdem_error_clear(&err);
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK) {
        FUZZ_CHECK(r == NULL && err.msg[0] != '\0');
        fuzz_rmdir(dir);
        return 0;
    }
    size_t n = cdem_h5_reader_increment_count(r);
    for (size_t k = 0; k < n; k++) {
        cdem_increment_info info;
        if (cdem_h5_reader_increment_info(r, k, &info, &err) != CDEM_OK)
            FUZZ_CHECK(err.msg[0] != '\0');
    }
    const char *specs[] = {"first", "last", "equil", "0", "1", "-1", "99999999999999999999", ""};
    for (size_t k = 0; k < sizeof specs / sizeof specs[0]; k++) {
        size_t index = SIZE_MAX;
        if (cdem_h5_reader_find_increment(r, specs[k], &index, &err) == CDEM_OK)
            FUZZ_CHECK(index < n);
    }
    for (size_t k = 0; k < n && k < 64; k++) {
        cdem_state s = {0};
        cdem_increment_info info;
        if (cdem_h5_reader_load_increment(r, k, &s, &info, &err) == CDEM_OK) {
            FUZZ_CHECK(info.n_elements == (int64_t)s.n);
            double sum = 0.0;
            for (size_t i = 0; i < s.n; i++)
                sum += s.x[i] + s.y[i] + s.radius[i] + s.id[i] + s.layer[i] + s.flags[i] +
                       s.born[i] + (s.has_stress ? s.sxx[i] + s.syy[i] + s.sxy[i] : 0.0);
            (void)sum;
        } else {
            FUZZ_CHECK(err.msg[0] != '\0');
        }
        cdem_state_free(&s);
    }
    cdem_series_sample *samples = NULL;
    size_t count = 0;
    if (cdem_h5_reader_read_series(r, &samples, &count, &err) == CDEM_OK && count > 0)
        FUZZ_CHECK(samples != NULL);
    free(samples);
    cdem_params p;
    if (cdem_h5_reader_params(r, &p, &err) != CDEM_OK)
        FUZZ_CHECK(err.msg[0] != '\0');
    cdem_snapshot *snap = NULL;
    int32_t ckpt_inc = 0;
    if (cdem_snapshot_alloc(&snap, &err) == CDEM_OK &&
        cdem_h5_reader_read_checkpoint(r, snap, &ckpt_inc, &err) != CDEM_OK)
        FUZZ_CHECK(err.msg[0] != '\0');
    cdem_snapshot_free(snap);
    int changed = 0;
    if (cdem_h5_reader_refresh(r, &changed, &err) != CDEM_OK)
        FUZZ_CHECK(err.msg[0] != '\0');
    size_t total = strlen(cdem_h5_reader_summary(r)) + strlen(cdem_h5_reader_params_text(r)) +
                   strlen(cdem_h5_reader_stop_reason(r)) +
                   strlen(cdem_h5_reader_program_version(r)) +
                   strlen(cdem_h5_reader_stop_detail(r)) + strlen(cdem_h5_reader_source(r)) +
                   strlen(cdem_h5_reader_created(r));
    (void)total;
    (void)cdem_h5_reader_seed(r);
    (void)cdem_h5_reader_unclosed(r);
    cdem_h5_reader_close(r);
    fuzz_rmdir(dir);
    return 0;
}
