/* Crash consistency of the run file (issue 35, item 1; docs/reliability.md, "Crash
 * consistency"): a writer killed at ANY write keeps every increment it committed, and the
 * file resumes to the file of an uninterrupted run. Not by luck: the test records every write
 * a short run makes to its file and then builds, write by write, the file a kill at that
 * moment leaves behind, in the way the ALICE study (Pillai et al., OSDI 2014) and SQLite's
 * crash tests construct crash states instead of waiting for a kill to land.
 *
 * The model of a kill (SIGKILL, or any end of the process): every write the process made
 * before is in the file (the page cache keeps it), nothing after; the write in progress may
 * be cut at a page boundary (the kernel copies a write into the page cache a page at a time
 * and checks for a fatal signal between pages), so each write that spans a page boundary is
 * also tried cut at each of its boundaries: the torn writes. A power cut is not modelled (it
 * can also reorder writes between two syncs; docs/reliability.md says what holds there).
 *
 * pwrite, ftruncate, fdatasync and fsync are interposed in this binary (the libraries are
 * linked statically, and the executable's definitions precede libc's for libhdf5, as in
 * test_durability.c); the run itself is made in-process by cdem_run, with its file's
 * checkpoints kept at the end (CDEM_KEEP_CHECKPOINTS) so that the whole run writes one file.
 *
 * At every crash state after the file was put in place (renamed from NAME.creating):
 *  - the file opens as a killed run's file, and its increments are those of the reference
 *    run, in order, each identical to it, and there are never fewer of them than were
 *    committed (synced) before that moment;
 *  - its series is a prefix of the reference's;
 *  - at every 250th state (make test; every 10th in make validate, every one with
 *    CDEM_CRASH_RESUME=all) cdem-run --resume on a copy either refuses for want of a
 *    checkpoint (nothing checkpointed yet) or ends with a file identical to the reference
 *    run's (or, killed after the stop reason "completed" was written, refuses because the
 *    run completed, and the file is the reference run's already). */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "h5format.h"
#include "params.h"
#include "run.h"
#include "scratch.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

/* ------------------------------------------------------------------ the recorded writes */

typedef enum { EV_WRITE, EV_TRUNCATE, EV_SYNC } event_kind;

typedef struct {
    event_kind kind;
    off_t offset;         /* EV_WRITE: where; EV_TRUNCATE: the new length */
    size_t len;           /* EV_WRITE: bytes */
    unsigned char *bytes; /* EV_WRITE: a copy of them */
} event;

/* Test instrumentation only (this binary's interposed calls write here). */
static struct {
    int recording;    /* 1 while the reference run is made */
    char match[1300]; /* the run file's path; its NAME.creating matches too */
    event *ev;        /* recorded events, in order */
    size_t n, cap;    /* used / allocated */
    long placed_at;   /* index of the first event after the file was put in place, -1 */
    char placed_name[1300];
} rec = {.placed_at = -1};

static int is_run_file(int fd) {
    char link[64], target[1200];
    snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
    ssize_t k = readlink(link, target, sizeof target - 1);
    if (k <= 0)
        return 0;
    target[k] = '\0';
    const size_t m = strlen(rec.match);
    return strncmp(target, rec.match, m) == 0 &&
           (target[m] == '\0' || strcmp(target + m, ".creating") == 0);
}

static void record(event e) {
    if (rec.n == rec.cap) {
        rec.cap = rec.cap ? 2 * rec.cap : 4096;
        rec.ev = realloc(rec.ev, rec.cap * sizeof *rec.ev);
        if (!rec.ev)
            abort();
    }
    /* the first write after the rename into place marks where crash states begin */
    if (rec.placed_at < 0 && access(rec.placed_name, F_OK) == 0)
        rec.placed_at = (long)rec.n;
    rec.ev[rec.n++] = e;
}

ssize_t pwrite(int fd, const void *buf, size_t n, off_t offset) {
    if (rec.recording && is_run_file(fd)) {
        event e = {EV_WRITE, offset, n, malloc(n ? n : 1)};
        if (!e.bytes)
            abort();
        memcpy(e.bytes, buf, n);
        record(e);
    }
    return (ssize_t)syscall(SYS_pwrite64, fd, buf, n, offset);
}

int ftruncate(int fd, off_t length) {
    if (rec.recording && is_run_file(fd))
        record((event){EV_TRUNCATE, length, 0, NULL});
    return (int)syscall(SYS_ftruncate, fd, length);
}

int fdatasync(int fd) {
    if (rec.recording && is_run_file(fd))
        record((event){EV_SYNC, 0, 0, NULL});
    return (int)syscall(SYS_fdatasync, fd);
}

int fsync(int fd) {
    if (rec.recording && is_run_file(fd))
        record((event){EV_SYNC, 0, 0, NULL});
    return (int)syscall(SYS_fsync, fd);
}

/* ------------------------------------------------------------------ the reference run */

typedef struct {
    scratch_dir dir;
    char ref[1200];             /* the reference run's file */
    size_t n_incr;              /* its increments */
    cdem_increment_info *info;  /* each one's row */
    cdem_state *states;         /* each one's elements */
    cdem_series_sample *series; /* its series */
    size_t n_series;            /* samples */
} crash_ctx;

/* The small model (1370 elements, 22 increments, a checkpoint every 3 increments). */
static const char *const MODEL[] = {
    "assembly.width=10",
    "assembly.height=2.5",
    "time.equilibration=100",
    "time.runtime=150",
    "output.series_interval=50",
    "physics.calculate_stress=on",
    "output.checkpoint_interval=3",
};

static void model_params(cdem_params *p) {
    cdem_params_defaults(p);
    cdem_error err;
    for (size_t i = 0; i < sizeof MODEL / sizeof MODEL[0]; i++)
        if (cdem_params_override(p, MODEL[i], &err) != CDEM_OK)
            fail_msg("%s", err.msg);
}

static cdem_run_options run_options(const char *path) {
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    o.log = stderr;
    o.ignore_free_space = 1;
    o.replace = CDEM_H5_REPLACE_ANY;
    return o;
}

static int setup(void **state) {
    crash_ctx *c = calloc(1, sizeof *c);
    if (!c || scratch_dir_make(&c->dir, "test_crash") != 0)
        return -1;
    setenv("CDEM_KEEP_CHECKPOINTS", "1", 1);
    setenv("OMP_NUM_THREADS", "1", 1);
    scratch_dir_path(&c->dir, c->ref, sizeof c->ref, "ref.h5");
    snprintf(rec.match, sizeof rec.match, "%s", c->ref);
    snprintf(rec.placed_name, sizeof rec.placed_name, "%s", c->ref);
    cdem_params p;
    model_params(&p);
    cdem_run_options o = run_options(c->ref);
    cdem_error err;
    rec.recording = 1;
    cdem_status st = cdem_run(&p, &o, &err);
    rec.recording = 0;
    if (st != CDEM_OK) {
        fprintf(stderr, "reference run: %s\n", err.msg);
        return -1;
    }
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(c->ref, &r, &err) != CDEM_OK)
        return -1;
    c->n_incr = cdem_h5_reader_increment_count(r);
    c->info = calloc(c->n_incr, sizeof *c->info);
    c->states = calloc(c->n_incr, sizeof *c->states);
    for (size_t k = 0; k < c->n_incr; k++)
        if (cdem_h5_reader_load_increment(r, k, &c->states[k], &c->info[k], &err) != CDEM_OK)
            return -1;
    if (cdem_h5_reader_read_series(r, &c->series, &c->n_series, &err) != CDEM_OK)
        return -1;
    cdem_h5_reader_close(r);
    *state = c;
    return 0;
}

static int teardown(void **state) {
    crash_ctx *c = *state;
    for (size_t k = 0; k < c->n_incr; k++)
        cdem_state_free(&c->states[k]);
    free(c->states);
    free(c->info);
    free(c->series);
    for (size_t i = 0; i < rec.n; i++)
        free(rec.ev[i].bytes);
    free(rec.ev);
    int rc = scratch_dir_remove(&c->dir);
    free(c);
    return rc;
}

/* ------------------------------------------------------------------ the checks */

static int same(const void *a, const void *b, size_t n) {
    return n == 0 || (a && b && memcmp(a, b, n) == 0);
}

/* 1 when increment k of the reference and (info, s) are the same bit for bit. */
static int same_increment(const crash_ctx *c, size_t k, const cdem_increment_info *in,
                          const cdem_state *s) {
    const cdem_increment_info *a = &c->info[k];
    const cdem_state *r = &c->states[k];
    const size_t n = r->n;
    return a->number == in->number && a->step == in->step && a->phase == in->phase &&
           same(&a->time, &in->time, 8) && same(&a->net_displacement, &in->net_displacement, 8) &&
           r->n == s->n && r->has_stress == s->has_stress && same(r->id, s->id, n * 4) &&
           same(r->x, s->x, n * 8) && same(r->y, s->y, n * 8) &&
           same(r->radius, s->radius, n * 8) && same(r->layer, s->layer, n * 4) &&
           same(r->flags, s->flags, n * 4) && same(r->born, s->born, n * 4) &&
           (!r->has_stress || (same(r->sxx, s->sxx, n * 8) && same(r->syy, s->syy, n * 8) &&
                               same(r->sxy, s->sxy, n * 8)));
}

/* Checks the crash state in path; returns its number of increments (fails the test when the
 * state is not one the promise allows). what says which state, for messages. */
static size_t check_state(const crash_ctx *c, const char *path, size_t at_least, const char *what) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s: the file does not open: %s", what, err.msg);
    const size_t n = cdem_h5_reader_increment_count(r);
    if (n < at_least || n > c->n_incr)
        fail_msg("%s: %zu increments listed, but %zu were committed before (the run wrote %zu)",
                 what, n, at_least, c->n_incr);
    for (size_t k = 0; k < n; k++) {
        cdem_state s;
        memset(&s, 0, sizeof s);
        cdem_increment_info in;
        if (cdem_h5_reader_load_increment(r, k, &s, &in, &err) != CDEM_OK)
            fail_msg("%s: increment %zu of %zu does not read back: %s", what, k, n, err.msg);
        if (!same_increment(c, k, &in, &s))
            fail_msg("%s: increment %zu differs from the reference run's", what, k);
        cdem_state_free(&s);
    }
    cdem_series_sample *q = NULL;
    size_t nq = 0;
    if (cdem_h5_reader_read_series(r, &q, &nq, &err) != CDEM_OK)
        fail_msg("%s: the series does not read back: %s", what, err.msg);
    if (nq > c->n_series || !same(q, c->series, nq * sizeof *q))
        fail_msg("%s: the series (%zu samples) is not a prefix of the reference's", what, nq);
    free(q);
    cdem_h5_reader_close(r);
    return n;
}

/* The file at path holds the reference run's increments and series and has completed. */
static void check_same_as_reference(const crash_ctx *c, const char *path, const char *what) {
    size_t n = check_state(c, path, c->n_incr, what);
    if (n != c->n_incr)
        fail_msg("%s: the resumed file has %zu increments, the reference %zu", what, n, c->n_incr);
    cdem_error err;
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    cdem_series_sample *q = NULL;
    size_t nq = 0;
    assert_int_equal(cdem_h5_reader_read_series(r, &q, &nq, &err), CDEM_OK);
    if (nq != c->n_series)
        fail_msg("%s: the resumed series has %zu samples, the reference %zu", what, nq,
                 c->n_series);
    free(q);
    if (strcmp(cdem_h5_reader_stop_reason(r), "completed") != 0)
        fail_msg("%s: the resumed run's stop reason is %s", what, cdem_h5_reader_stop_reason(r));
    cdem_h5_reader_close(r);
}

/* Resumes a copy of the crash state in path and checks the result. */
static int check_resume(const crash_ctx *c, const char *path, const char *what) {
    char copy[1300], cmd[3000];
    scratch_dir_path(&c->dir, copy, sizeof copy, "resumed.h5");
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", path, copy);
    assert_int_equal(system(cmd), 0);
    cdem_run_options o = run_options(copy);
    cdem_error err;
    cdem_status st = cdem_run_resume(copy, &o, &err);
    if (st == CDEM_ERR_NOTFOUND && strstr(err.msg, "no checkpoint"))
        return 0; /* killed before the first checkpoint: nothing to resume from */
    if (st == CDEM_ERR_CONFLICT && strstr(err.msg, "already completed")) {
        /* killed after the stop reason "completed" (while closing): it is the whole run */
        check_same_as_reference(c, path, what);
        return 1;
    }
    if (st != CDEM_OK)
        fail_msg("%s: the resume failed: %s", what, err.msg);
    check_same_as_reference(c, copy, what);
    return 1;
}

static void put(int fd, const void *bytes, size_t len, off_t at) {
    if ((size_t)syscall(SYS_pwrite64, fd, bytes, len, at) != len)
        fail_msg("writing the crash state: %s", strerror(errno));
}

/* Every crash state of the recorded run: each prefix of its writes, and each write torn at
 * each page boundary inside it. resume_every: resume the states whose number is a multiple
 * of it (1: all). */
static void crash_states(const crash_ctx *c, long resume_every) {
    assert_true(rec.placed_at > 0);
    char path[1300];
    scratch_dir_path(&c->dir, path, sizeof path, "crash.h5");
    int fd = open(path, O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    assert_true(fd >= 0);
    const long page = sysconf(_SC_PAGESIZE);
    size_t committed = 0; /* increments listed at the last sync: never fewer afterwards */
    size_t listed = 0, states = 0, torn_states = 0, resumed = 0;
    for (size_t i = 0; i < rec.n; i++) {
        const event *e = &rec.ev[i];
        char what[200];
        if ((long)i >= rec.placed_at && e->kind == EV_WRITE) {
            /* the write torn at each page boundary inside it */
            for (off_t b = (e->offset / page + 1) * page; b < e->offset + (off_t)e->len;
                 b += page) {
                const size_t part = (size_t)(b - e->offset);
                unsigned char *old = malloc(part);
                assert_non_null(old);
                ssize_t got = pread(fd, old, part, e->offset);
                put(fd, e->bytes, part, e->offset);
                snprintf(what, sizeof what,
                         "event %zu (a write of %zu bytes at %lld, torn after %zu)", i, e->len,
                         (long long)e->offset, part);
                check_state(c, path, committed, what);
                torn_states++;
                /* back as before the write (bytes past the old end of the file as zeros) */
                memset(old + (got > 0 ? got : 0), 0, part - (size_t)(got > 0 ? got : 0));
                put(fd, old, part, e->offset);
                free(old);
            }
        }
        if ((long)i >= rec.placed_at) {
            snprintf(what, sizeof what, "before event %zu of %zu", i, rec.n);
            listed = check_state(c, path, committed, what);
            if (resume_every > 0 && (long)states % resume_every == 0)
                resumed += (size_t)check_resume(c, path, what);
            states++;
        }
        if (e->kind == EV_WRITE)
            put(fd, e->bytes, e->len, e->offset);
        else if (e->kind == EV_TRUNCATE)
            assert_int_equal(syscall(SYS_ftruncate, fd, e->offset), 0);
        else if ((long)i >= rec.placed_at)
            committed = listed; /* what was there at a sync is committed */
    }
    close(fd);
    listed = check_state(c, path, committed, "the complete run");
    assert_int_equal(listed, c->n_incr);
    print_message("crash states: %zu events recorded (%zu after the file was in place), %zu states "
                  "and %zu torn writes checked, %zu states resumed to the reference file\n",
                  rec.n, rec.n - (size_t)rec.placed_at, states, torn_states, resumed);
}

static void test_crash_every_write_keeps_committed_increments(void **state) {
    const crash_ctx *c = *state;
    /* CDEM_CRASH_RESUME: resume every Nth state, or "all"; make test: every 250th (about
     * 9 of the 2,213 states), make validate: every 10th */
    const char *mode = getenv("CDEM_CRASH_RESUME");
    long every = 250;
    if (mode && strcmp(mode, "all") == 0)
        every = 1;
    else if (mode && atol(mode) > 0)
        every = atol(mode);
    crash_states(c, every);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crash_every_write_keeps_committed_increments),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
