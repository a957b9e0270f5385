/* Durability of commits (issue 19, item 9; docs/reliability.md, "Power cuts"): the writer
 * flushes an increment's data to stable storage before its index row (the commit record),
 * and the row itself after, so a power cut (not only a killed process) keeps every
 * committed increment; the same for checkpoints and the stop reason. cdem_h5_writer_set_sync
 * (cdem-run --no-fsync) turns that off. fsync, fdatasync and pwrite are interposed in this
 * test binary (the library is linked statically, so its calls bind to the definitions below;
 * and the executable's pwrite precedes libc's for libhdf5): the test records the order of the
 * writes and flushes of each commit. */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "h5format.h"
#include "scratch.h"

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

/* Test instrumentation only: fsync/fdatasync calls on regular files and folders since the
 * last reset, and the sequence of file writes ('w') and file flushes to the disk ('f'). */
static int fsync_files, fsync_folders;
static char events[4096];
static size_t n_events;

static void event(char e) {
    if (n_events + 1 < sizeof events && (n_events == 0 || events[n_events - 1] != e || e == 'f'))
        events[n_events++] = e; /* runs of writes count as one */
    events[n_events] = '\0';
}

static void reset(void) {
    fsync_files = fsync_folders = 0;
    n_events = 0;
    events[0] = '\0';
}

static void count_sync(int fd) {
    struct stat sb;
    if (fstat(fd, &sb) == 0 && S_ISDIR(sb.st_mode)) {
        fsync_folders++;
    } else {
        fsync_files++;
        event('f');
    }
}

int fsync(int fd) {
    count_sync(fd);
    return (int)syscall(SYS_fsync, fd);
}

int fdatasync(int fd) {
    count_sync(fd);
    return (int)syscall(SYS_fdatasync, fd);
}

ssize_t pwrite(int fd, const void *buf, size_t n, off_t offset) {
    event('w');
    return (ssize_t)syscall(SYS_pwrite64, fd, buf, n, offset);
}

static void make_state(cdem_state *s, size_t n) {
    memset(s, 0, sizeof *s);
    cdem_error err;
    assert_int_equal(cdem_state_init(s, n, 0, &err), CDEM_OK);
    for (size_t i = 0; i < n; i++)
        assert_int_equal(
            cdem_state_append(s, (int32_t)i, 10.0 * (double)i, 5.0, 1.0, 1.0, 1, 0u, 0, NULL, &err),
            CDEM_OK);
}

static cdem_increment_info info_of(int k) {
    cdem_increment_info in = {0};
    in.number = k;
    in.step = 100 * k;
    in.time = 0.5 * k;
    in.sea_level = 0.0;
    return in;
}

static void test_durability_every_commit_reaches_the_disk(void **state) {
    (void)state;
    char path[1024], xmf[1100];
    scratch_path(path, sizeof path, "durable.h5");
    snprintf(xmf, sizeof xmf, "%.*s.xmf", (int)(strlen(path) - 3), path);
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, NULL, "s", "v", "cdem-run", 0};
    cdem_error err;
    cdem_h5_writer *w = NULL;
    reset();
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    /* the new file, and the folder entry of its name */
    assert_true(fsync_files >= 1);
    assert_true(fsync_folders >= 1);
    cdem_state s;
    make_state(&s, 50);
    for (int k = 0; k < 4; k++) {
        reset();
        cdem_increment_info in = info_of(k);
        assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_OK);
        /* the data written and flushed to the disk, then the commit record written and
         * flushed: no write of the record can reach the disk before the data */
        if (strcmp(events, "wfwf") != 0)
            fail_msg("increment %d: writes (w) and flushes to disk (f) in the order %s, expected "
                     "wfwf",
                     k, events);
        assert_int_equal(fsync_files, 2);
    }
    cdem_snapshot *snap = NULL;
    assert_int_equal(cdem_snapshot_alloc(&snap, &err), CDEM_OK);
    const double v[3] = {1, 2, 3};
    assert_int_equal(cdem_snapshot_put(snap, "x.v", CDEM_SNAP_F64, 3, v, &err), CDEM_OK);
    reset();
    assert_int_equal(cdem_h5_writer_write_checkpoint(w, snap, &err), CDEM_OK);
    assert_string_equal(events, "wfwf"); /* the slot, then its index row */
    cdem_snapshot_free(snap);
    reset();
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, "completed", "", &err), CDEM_OK);
    assert_string_equal(events, "wf");

    /* --no-fsync: no flush to the disk at commits */
    cdem_h5_writer_set_sync(w, 0);
    reset();
    cdem_increment_info in = info_of(4);
    assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, "completed", "", &err), CDEM_OK);
    assert_int_equal(fsync_files, 0);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
    cdem_state_free(&s);
    remove(path);
    remove(xmf);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_durability_every_commit_reaches_the_disk),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
