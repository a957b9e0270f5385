/* Tests of cdem-run --resume and of determinism, with the program ($CDEM_BUILD/cdem-run):
 *  - the same small run with OMP_NUM_THREADS = 1, 2 and 3 and --par-min 64 (so the threaded
 *    loops really run threaded) gives identical files: every increment's attributes and
 *    datasets, the series, the texts and the newest checkpoint (compared through the reader;
 *    the creation time is the only attribute left out);
 *  - a run SIGKILLed after a checkpoint, or stopped by --max-steps, and resumed gives the
 *    file (and newest checkpoint) of an uninterrupted run; an interrupted or stopped run keeps
 *    its checkpoints, a completed one drops them (its values are those of a run that keeps
 *    them, CDEM_KEEP_CHECKPOINTS=1) and cannot be resumed;
 *  - refused resumes: a completed run, -s overrides, a model file, -o, a missing file, a
 *    non-HDF5 file, a file without checkpoint, each with its message and exit status.
 * Scratch files go to a private directory under $CDEM_TEST_TMP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "h5format.h"

#include <hdf5.h>
#include "snapshot.h"
#include "scratch.h"

#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef struct {
    char bin[1024];      /* path of cdem-run */
    scratch_dir scratch; /* private scratch directory */
} rs_ctx;

/* cdem-run's environment to keep a completed run's checkpoints (h5format.h) */
#define KEEP "CDEM_KEEP_CHECKPOINTS=1"

/* The small model every test runs (1370 elements, 5322 steps, 22 increments). */
#define SMALL                                                                                      \
    "-s assembly.width=10 -s assembly.height=2.5 -s time.equilibration=100 "                       \
    "-s time.runtime=150 -s output.series_interval=50 -s "                                         \
    "physics.calculate_stress=on"

static int setup(void **state) {
    rs_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    char rel[1024];
    snprintf(rel, sizeof rel, "%s/cdem-run", b && b[0] ? b : "build");
    if (!realpath(rel, c->bin)) /* the tests cd into their scratch directory */
        snprintf(c->bin, sizeof c->bin, "%s", rel);
    if (scratch_dir_make(&c->scratch, "test_resume") != 0) {
        free(c);
        return -1;
    }
    *state = c;
    return 0;
}

static int teardown(void **state) {
    rs_ctx *c = *state;
    int rc = scratch_dir_remove(&c->scratch);
    free(c);
    return rc;
}

/* Runs "env ENV cdem-run ARGS" (shell syntax) with stderr to tmp/err.txt; the
 * exit status. */
static int run(const rs_ctx *c, const char *env, const char *args) {
    if (access(c->bin, X_OK) != 0) {
        print_error("%s is missing: build it first (make build/cdem-run)\n", c->bin);
        fail();
    }
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "cd '%s' && env OMP_WAIT_POLICY=passive %s '%s' %s 2>'%s/err.txt'",
             c->scratch.dir, env ? env : "", c->bin, args, c->scratch.dir);
    int st = system(cmd);
    assert_true(WIFEXITED(st));
    return WEXITSTATUS(st);
}

static char *slurp(const rs_ctx *c, const char *name) {
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", c->scratch.dir, name);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char *buf = calloc(1, 1 << 16);
    assert_non_null(buf);
    size_t n = fread(buf, 1, (1 << 16) - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static void expect_err(const rs_ctx *c, const char *needle) {
    char *e = slurp(c, "err.txt");
    if (!strstr(e, needle))
        fail_msg("stderr lacks \"%s\":\n%s", needle, e);
    free(e);
}

static void path_of(const rs_ctx *c, const char *name, char *buf, size_t n) {
    snprintf(buf, n, "%s/%s", c->scratch.dir, name);
}

#define SAME_BITS(a, b, what, ...)                                                                 \
    do {                                                                                           \
        if (memcmp(&(a), &(b), sizeof(a)) != 0)                                                    \
            fail_msg(what, __VA_ARGS__);                                                           \
    } while (0)

static void same_array(const void *a, const void *b, size_t n, size_t size, const char *what,
                       int inc) {
    if (n == 0)
        return;
    if ((a == NULL) != (b == NULL))
        fail_msg("increment %d: %s present in one file only", inc, what);
    if (a && memcmp(a, b, n * size) != 0)
        fail_msg("increment %d: dataset %s differs", inc, what);
}

/* Every increment (attributes and datasets), the series and the texts of two
 * files are identical bit for bit; only the creation time may differ. */
static void compare_contents(const char *pa, const char *pb, int with_texts);

static void compare_files(const char *pa, const char *pb) {
    compare_contents(pa, pb, 1);
}

/* The same, texts (summary, parameter file text) left out when with_texts is 0: a file
 * written by an earlier build has the same values but may word its help comments otherwise. */
static void compare_contents(const char *pa, const char *pb, int with_texts) {
    cdem_error err;
    cdem_h5_reader *a = NULL, *b = NULL;
    if (cdem_h5_reader_open(pa, &a, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    if (cdem_h5_reader_open(pb, &b, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    assert_string_equal(cdem_h5_reader_stop_reason(a), cdem_h5_reader_stop_reason(b));
    assert_string_equal(cdem_h5_reader_stop_detail(a), cdem_h5_reader_stop_detail(b));
    if (with_texts) {
        assert_string_equal(cdem_h5_reader_summary(a), cdem_h5_reader_summary(b));
        assert_string_equal(cdem_h5_reader_params_text(a), cdem_h5_reader_params_text(b));
    }
    assert_string_equal(cdem_h5_reader_program_version(a), cdem_h5_reader_program_version(b));
    const size_t n = cdem_h5_reader_increment_count(a);
    assert_int_equal(n, cdem_h5_reader_increment_count(b));
    assert_true(n > 3);
    for (size_t k = 0; k < n; k++) {
        cdem_state sa, sb;
        memset(&sa, 0, sizeof sa);
        memset(&sb, 0, sizeof sb);
        cdem_increment_info ia, ib;
        if (cdem_h5_reader_load_increment(a, k, &sa, &ia, &err) != CDEM_OK ||
            cdem_h5_reader_load_increment(b, k, &sb, &ib, &err) != CDEM_OK)
            fail_msg("%s", err.msg);
        const int num = ia.number;
        assert_int_equal(ia.number, ib.number);
        assert_int_equal(ia.step, ib.step);
        assert_int_equal(ia.phase, ib.phase);
        SAME_BITS(ia.time, ib.time, "increment %d: time differs", num);
        SAME_BITS(ia.net_displacement, ib.net_displacement, "increment %d: net differs", num);
        SAME_BITS(ia.axial_strain, ib.axial_strain, "increment %d: axial strain differs", num);
        SAME_BITS(ia.differential_stress, ib.differential_stress, "increment %d: stress differs",
                  num);
        SAME_BITS(ia.sea_level, ib.sea_level, "increment %d: sea level differs", num);
        assert_int_equal(sa.n, sb.n);
        assert_int_equal(sa.has_stress, sb.has_stress);
        same_array(sa.id, sb.id, sa.n, sizeof *sa.id, "id", num);
        same_array(sa.x, sb.x, sa.n, sizeof *sa.x, "x", num);
        same_array(sa.y, sb.y, sa.n, sizeof *sa.y, "y", num);
        same_array(sa.radius, sb.radius, sa.n, sizeof *sa.radius, "radius", num);
        same_array(sa.layer, sb.layer, sa.n, sizeof *sa.layer, "layer", num);
        same_array(sa.flags, sb.flags, sa.n, sizeof *sa.flags, "flags", num);
        same_array(sa.born, sb.born, sa.n, sizeof *sa.born, "born", num);
        if (sa.has_stress) {
            same_array(sa.sxx, sb.sxx, sa.n, sizeof *sa.sxx, "sxx", num);
            same_array(sa.syy, sb.syy, sa.n, sizeof *sa.syy, "syy", num);
            same_array(sa.sxy, sb.sxy, sa.n, sizeof *sa.sxy, "sxy", num);
        }
        cdem_state_free(&sa);
        cdem_state_free(&sb);
    }
    cdem_series_sample *qa = NULL, *qb = NULL;
    size_t na = 0, nb = 0;
    if (cdem_h5_reader_read_series(a, &qa, &na, &err) != CDEM_OK ||
        cdem_h5_reader_read_series(b, &qb, &nb, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(na, nb);
    assert_true(na > 10);
    for (size_t k = 0; k < na; k++) {
        const cdem_series_sample *x = &qa[k], *y = &qb[k];
        const long st = (long)x->step;
        assert_int_equal(x->step, y->step);
        assert_int_equal(x->contacts, y->contacts);
        assert_int_equal(x->bonds, y->bonds);
        assert_int_equal(x->n_elements, y->n_elements);
        SAME_BITS(x->time, y->time, "series step %ld: time differs", st);
        SAME_BITS(x->kinetic_energy, y->kinetic_energy, "series step %ld: energy differs", st);
        SAME_BITS(x->net_displacement, y->net_displacement, "series step %ld: net differs", st);
        SAME_BITS(x->boundary_force_x, y->boundary_force_x, "series step %ld: force differs", st);
        SAME_BITS(x->boundary_force_y, y->boundary_force_y, "series step %ld: force differs", st);
        SAME_BITS(x->base_force_x, y->base_force_x, "series step %ld: base force differs", st);
        SAME_BITS(x->base_force_y, y->base_force_y, "series step %ld: base force differs", st);
        SAME_BITS(x->axial_strain, y->axial_strain, "series step %ld: strain differs", st);
        SAME_BITS(x->differential_stress, y->differential_stress, "series step %ld: differs", st);
        SAME_BITS(x->sea_level, y->sea_level, "series step %ld: sea level differs", st);
    }
    free(qa);
    free(qb);
    cdem_h5_reader_close(a);
    cdem_h5_reader_close(b);
}

static void compare_checkpoints(const char *pa, const char *pb);

static void test_resume_determinism_threads_1_2_3(void **state) {
    const rs_ctx *c = *state;
    char p1[1200], p2[1200], p3[1200];
    assert_int_equal(
        run(c, "OMP_NUM_THREADS=1 CDEM_KEEP_CHECKPOINTS=1", "-q -o t1.h5 --par-min 64 " SMALL), 0);
    assert_int_equal(
        run(c, "OMP_NUM_THREADS=2 CDEM_KEEP_CHECKPOINTS=1", "-q -o t2.h5 --par-min 64 " SMALL), 0);
    assert_int_equal(
        run(c, "OMP_NUM_THREADS=3 CDEM_KEEP_CHECKPOINTS=1", "-q -o t3.h5 --par-min 64 " SMALL), 0);
    path_of(c, "t1.h5", p1, sizeof p1);
    path_of(c, "t2.h5", p2, sizeof p2);
    path_of(c, "t3.h5", p3, sizeof p3);
    compare_files(p1, p2);
    compare_files(p1, p3);
    /* the newest checkpoints (default: every 10 increments) hold velocities, forces and the
     * contact histories: identical too */
    compare_checkpoints(p1, p2);
    compare_checkpoints(p1, p3);
}

/* The newest checkpoints of two files are identical (and exist). */
static void compare_checkpoints(const char *pa, const char *pb) {
    cdem_error err;
    cdem_h5_reader *a = NULL, *b = NULL;
    cdem_snapshot *sa = NULL, *sb = NULL;
    assert_int_equal(cdem_snapshot_alloc(&sa, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_alloc(&sb, &err), CDEM_OK);
    if (cdem_h5_reader_open(pa, &a, &err) != CDEM_OK ||
        cdem_h5_reader_open(pb, &b, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    int32_t ia = -1, ib = -2;
    if (cdem_h5_reader_read_checkpoint(a, sa, &ia, &err) != CDEM_OK ||
        cdem_h5_reader_read_checkpoint(b, sb, &ib, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(ia, ib);
    const char *diff = NULL;
    if (!cdem_snapshot_equal(sa, sb, &diff))
        fail_msg("checkpoints of increment %d differ in %s", (int)ia, diff ? diff : "?");
    cdem_snapshot_free(sa);
    cdem_snapshot_free(sb);
    cdem_h5_reader_close(a);
    cdem_h5_reader_close(b);
}

/* What reading the newest checkpoint of path returns (CDEM_OK: it has one). */
static cdem_status checkpoint_status(const char *path) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    cdem_snapshot *snap = NULL;
    assert_int_equal(cdem_snapshot_alloc(&snap, &err), CDEM_OK);
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    int32_t inc = -1;
    cdem_status st = cdem_h5_reader_read_checkpoint(r, snap, &inc, &err);
    if (st == CDEM_ERR_NOTFOUND && !strstr(err.msg, "checkpoints were dropped"))
        fail_msg("no checkpoint, but not said to be dropped: %s", err.msg);
    cdem_snapshot_free(snap);
    cdem_h5_reader_close(r);
    return st;
}

/* 1 when the file contains needle. */
static int file_has(const char *path, const char *needle) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    const size_t cap = 1 << 16;
    char *buf = calloc(1, cap);
    assert_non_null(buf);
    size_t n = fread(buf, 1, cap - 1, f);
    buf[n] = '\0';
    fclose(f);
    const int has = strstr(buf, needle) != NULL;
    free(buf);
    return has;
}

/* Starts cdem-run on the small model (checkpoint every 2 increments) writing name.h5, its
 * log to name.log, sends sig as soon as the log reports the end of equilibration (several
 * increments and at least one checkpoint are in the file by then; a third of the run is
 * left) and returns its wait status. */
static int start_and_signal_force(const rs_ctx *c, const char *name, int sig, int force);

static int start_and_signal(const rs_ctx *c, const char *name, int sig) {
    return start_and_signal_force(c, name, sig, 0);
}

/* The same, with --force when force. */
static int start_and_signal_force(const rs_ctx *c, const char *name, int sig, int force) {
    char log[1200], out[1200], base[64];
    snprintf(base, sizeof base, "%s.log", name);
    path_of(c, base, log, sizeof log);
    snprintf(base, sizeof base, "%s.h5", name);
    path_of(c, base, out, sizeof out);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        FILE *f = freopen(log, "wb", stderr);
        if (!f || chdir(c->scratch.dir) != 0)
            _exit(99);
        char *argv[24];
        int k = 0;
        const char *args[] = {"-o", out,
                              "-s", "output.checkpoint_interval=2",
                              "-s", "assembly.width=10",
                              "-s", "assembly.height=2.5",
                              "-s", "time.equilibration=100",
                              "-s", "time.runtime=150",
                              "-s", "output.series_interval=50",
                              "-s", "physics.calculate_stress=on"};
        argv[k++] = (char *)c->bin;
        for (size_t i = 0; i < sizeof args / sizeof args[0]; i++)
            argv[k++] = (char *)args[i];
        if (force)
            argv[k++] = (char *)"--force";
        argv[k] = NULL;
        execv(c->bin, argv);
        _exit(98);
    }
    int sent = 0;
    for (int i = 0; i < 60000 && !sent; i++) {
        int st = 0;
        if (waitpid(pid, &st, WNOHANG) == pid)
            fail_msg("cdem-run ended (status %d) before it could be signalled", st);
        if (file_has(log, "end of equilibration")) {
            assert_int_equal(kill(pid, sig), 0);
            sent = 1;
        } else {
            const struct timespec ts = {0, 5000000};
            nanosleep(&ts, NULL);
        }
    }
    assert_true(sent);
    int st = 0;
    assert_int_equal(waitpid(pid, &st, 0), pid);
    return st;
}

/* The run straight; the same run SIGKILLed mid-run (after at least one checkpoint) and
 * resumed, and SIGINTed (stop reason "interrupted", exit 3) and resumed: each gives the
 * straight run's increments, series and newest checkpoint. */
static void test_resume_after_sigkill_is_bit_identical(void **state) {
    const rs_ctx *c = *state;
    /* completed runs keep their checkpoints only with CDEM_KEEP_CHECKPOINTS (docs/format.md,
     * "Completed runs"): kept here to compare them */
    assert_int_equal(run(c, KEEP, "-q -o straight.h5 -s output.checkpoint_interval=2 " SMALL), 0);
    char ps[1200], pk[1200], pi[1200];
    path_of(c, "straight.h5", ps, sizeof ps);
    path_of(c, "killed.h5", pk, sizeof pk);
    path_of(c, "stopped.h5", pi, sizeof pi);

    int st = start_and_signal(c, "killed", SIGKILL);
    assert_true(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
    assert_int_equal(run(c, KEEP, "-q --resume killed.h5"), 0);
    compare_files(ps, pk);
    compare_checkpoints(ps, pk);
    /* and now it is complete */
    assert_int_equal(run(c, NULL, "--resume killed.h5"), 1);
    expect_err(c, "already completed");

    st = start_and_signal(c, "stopped", SIGINT);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 3);
    cdem_h5_reader *r = NULL;
    cdem_error err;
    assert_int_equal(cdem_h5_reader_open(pi, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "interrupted");
    cdem_h5_reader_close(r);
    assert_int_equal(checkpoint_status(pi), CDEM_OK); /* an interrupted run keeps them */
    /* resumed to completion with the default: the checkpoints are dropped, the file is
     * compacted, every value is the straight run's */
    assert_int_equal(run(c, NULL, "-q --resume stopped.h5"), 0);
    compare_files(ps, pi);
    assert_int_equal(checkpoint_status(pi), CDEM_ERR_NOTFOUND);
    struct stat sa, sb;
    assert_int_equal(stat(ps, &sa), 0);
    assert_int_equal(stat(pi, &sb), 0);
    if (sb.st_size >= sa.st_size)
        fail_msg("the compacted file has %lld bytes, the one with checkpoints %lld",
                 (long long)sb.st_size, (long long)sa.st_size);
    char leftover[1300];
    snprintf(leftover, sizeof leftover, "%s.compacting", pi);
    assert_int_not_equal(access(leftover, F_OK), 0);
    assert_int_equal(run(c, NULL, "--resume stopped.h5"), 1);
    expect_err(c, "already completed");
}

/* Stopped by --max-steps between checkpoints (its stop checkpoint is the
 * newest) and resumed: the uninterrupted run's file and newest checkpoint. */
static void test_resume_after_max_steps_is_bit_identical(void **state) {
    const rs_ctx *c = *state;
    assert_int_equal(run(c, KEEP, "-q -o straight3.h5 -s output.checkpoint_interval=3 " SMALL), 0);
    assert_int_equal(run(c, KEEP,
                         "-q -o early.h5 --max-steps 4321 -s "
                         "output.checkpoint_interval=3 " SMALL),
                     0);
    char pe[1200], ps[1200];
    path_of(c, "early.h5", pe, sizeof pe);
    path_of(c, "straight3.h5", ps, sizeof ps);
    cdem_h5_reader *r = NULL;
    cdem_error err;
    assert_int_equal(cdem_h5_reader_open(pe, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "stopped-early");
    cdem_h5_reader_close(r);
    assert_int_equal(checkpoint_status(pe), CDEM_OK); /* stopped early: kept */
    assert_int_equal(run(c, KEEP, "-q --resume early.h5"), 0);
    compare_files(ps, pe);
    compare_checkpoints(ps, pe);
}

/* A run with salt (the salt's area ratio J in the checkpoint, its module's grid and pairs
 * rebuilt from the restored list, contact damping) stopped by --max-steps in its deformation
 * phase and resumed: the uninterrupted run's file and newest checkpoint, bit for bit. */
static void test_resume_salt_is_bit_identical(void **state) {
    const rs_ctx *c = *state;
#define SALT                                                                                       \
    SMALL " -s salt.layer=basal -s physics.damping_mode=contact -s boundary.mode=detachment"
    assert_int_equal(run(c, KEEP, "-q -o salt_straight.h5 -s output.checkpoint_interval=3 " SALT),
                     0);
    assert_int_equal(
        run(c, KEEP, "-q -o salt_early.h5 --max-steps 4700 -s output.checkpoint_interval=3 " SALT),
        0);
#undef SALT
    char pe[1200], ps[1200];
    path_of(c, "salt_early.h5", pe, sizeof pe);
    path_of(c, "salt_straight.h5", ps, sizeof ps);
    assert_int_equal(run(c, KEEP, "-q --resume salt_early.h5"), 0);
    compare_files(ps, pe);
    compare_checkpoints(ps, pe);
}

static void test_resume_refusals(void **state) {
    const rs_ctx *c = *state;
    /* a completed run */
    assert_int_equal(
        run(c, NULL, "-q -o done.h5 --max-steps 1 -s output.checkpoint_interval=0 " SMALL), 0);
    assert_int_equal(run(c, NULL,
                         "-q -o full.h5 -s time.runtime=100.5 -s assembly.width=10 "
                         "-s assembly.height=2.5 -s time.equilibration=100"),
                     0);
    assert_int_equal(run(c, NULL, "--resume full.h5"), 1);
    expect_err(c, "already completed");
    /* overrides, a model file and -o cannot be combined with --resume */
    assert_int_equal(run(c, NULL, "--resume done.h5 -s time.runtime=300"), 2);
    expect_err(c, "-s overrides");
    assert_int_equal(run(c, NULL, "model.ini --resume done.h5"), 2);
    expect_err(c, "a model file");
    assert_int_equal(run(c, NULL, "--resume done.h5 -o other.h5"), 2);
    expect_err(c, "-o");
    assert_int_equal(run(c, NULL, "--resume"), 2);
    expect_err(c, "needs the run file");
    /* a missing file, a file that is not HDF5 */
    assert_int_equal(run(c, NULL, "--resume missing.h5"), 1);
    expect_err(c, "missing.h5");
    assert_int_equal(run(c, NULL, "--resume err.txt"), 1);
    expect_err(c, "err.txt");
    /* written without checkpoints (and stopped after 1 step): nothing to resume
     * from */
    assert_int_equal(run(c, NULL, "--resume done.h5"), 1);
    expect_err(c, "has no checkpoint to resume from");
    /* the refused resume left the file as it was */
    char p[1200];
    path_of(c, "done.h5", p, sizeof p);
    cdem_h5_reader *r = NULL;
    cdem_error err;
    assert_int_equal(cdem_h5_reader_open(p, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "stopped-early");
    assert_int_equal(cdem_h5_reader_increment_count(r), 2);
    cdem_h5_reader_close(r);
}

/* A run stopped by a file size limit (ulimit -f: its writes past the limit fail, the file
 * ends where the limit cut it although its superblock records more) is resumed, once the
 * limit is lifted, to the file of an uninterrupted run (issue 35, item 3: it was refused as
 * "truncated"). */
static void test_resume_after_file_size_limit_is_bit_identical(void **state) {
    const rs_ctx *c = *state;
    assert_int_equal(run(c, KEEP, "-q -o whole.h5 -s output.checkpoint_interval=2 " SMALL), 0);
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && bash -c 'ulimit -f 1000; exec env OMP_WAIT_POLICY=passive %s \"%s\" -q "
             "-o limited.h5 -s output.checkpoint_interval=2 %s' 2>'%s/err.txt'",
             c->scratch.dir, KEEP, c->bin, SMALL, c->scratch.dir);
    int st = system(cmd);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 1);
    expect_err(c, "limited.h5");
    char pw[1200], pl[1200];
    path_of(c, "whole.h5", pw, sizeof pw);
    path_of(c, "limited.h5", pl, sizeof pl);
    cdem_h5_reader *r = NULL;
    cdem_error err;
    assert_int_equal(cdem_h5_reader_open(pl, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "write-failure");
    const size_t kept = cdem_h5_reader_increment_count(r);
    cdem_h5_reader_close(r);
    assert_true(kept > 2);
    struct stat sb;
    assert_int_equal(stat(pl, &sb), 0);
    assert_true(sb.st_size <= 1000 * 1024);
    if (run(c, KEEP, "-q --resume limited.h5") != 0) {
        char *e = slurp(c, "err.txt");
        fail_msg("the resume of a run stopped by a size limit failed:\n%s", e);
    }
    compare_files(pw, pl);
    compare_checkpoints(pw, pl);
}

/* The file offset of chunk `chunk` of dataset name in the killed run's file at path. */
static long chunk_at(const char *path, const char *name, hsize_t chunk) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    hbool_t yes = 1; /* a killed writer's file: read it as the reader does */
    H5Pset(fapl, "clear_status_flags", &yes);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    H5Pclose(fapl);
    assert_true(f >= 0);
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    hid_t sp = H5Dget_space(ds);
    hsize_t offset = 0, size = 0;
    unsigned mask = 0;
    haddr_t addr = HADDR_UNDEF;
    assert_true(H5Dget_chunk_info(ds, sp, chunk, &offset, &mask, &addr, &size) >= 0);
    H5Sclose(sp);
    H5Dclose(ds);
    H5Fclose(f);
    return (long)addr + (long)size / 2;
}

/* The file of issue 35, item 1 (tests/data/k20_torn_index.h5.gz): a run of the default model
 * at assembly.height = 2.5, equilibration 600 s, runtime 2000 s, SIGKILLed 2.87 s in, while
 * it rewrote the single chunk of /increments/index: rows 0..30 in the chunk, the checksum
 * that of the 30-row chunk. Every reader and --resume refused the whole file ("no increment
 * of this file can be trusted"). Its 30 increments read back (the stored checksum is
 * recomputed over the rows it covered), and the resume ends with the file of an
 * uninterrupted run. */
static void test_resume_torn_index_evidence(void **state) {
    const rs_ctx *c = *state;
    const char *data = getenv("CDEM_TEST_DATA");
    char cmd[3000], p[1200];
    path_of(c, "k20.h5", p, sizeof p);
    snprintf(cmd, sizeof cmd, "gzip -dc '%s/k20_torn_index.h5.gz' > '%s'",
             data && *data ? data : "tests/data", p);
    assert_int_equal(system(cmd), 0);
    cdem_h5_reader *r = NULL;
    cdem_error err;
    if (cdem_h5_reader_open(p, &r, &err) != CDEM_OK)
        fail_msg("the torn file does not open: %s", err.msg);
    assert_int_equal(cdem_h5_reader_increment_count(r), 30);
    for (size_t k = 0; k < 30; k++) {
        cdem_state s;
        memset(&s, 0, sizeof s);
        cdem_increment_info in;
        if (cdem_h5_reader_load_increment(r, k, &s, &in, &err) != CDEM_OK)
            fail_msg("increment %zu: %s", k, err.msg);
        assert_int_equal(in.number, (int)k);
        assert_int_equal(s.n, 1288);
        cdem_state_free(&s);
    }
    cdem_h5_reader_close(r);
    assert_int_equal(run(c, NULL, "-q --resume k20.h5"), 0);
    assert_int_equal(run(c, NULL,
                         "-q -o k20fresh.h5 -s assembly.height=2.5 -s time.equilibration=600 -s "
                         "time.runtime=2000"),
                     0);
    char fresh[1200];
    path_of(c, "k20fresh.h5", fresh, sizeof fresh);
    /* the evidence was written before the law rows worded the help of granular_law */
    compare_contents(fresh, p, 0);
}

/* Stop reason and increment count of the run file at path. */
static void stop_and_count(const char *path, char *stop, size_t cap, size_t *n) {
    cdem_h5_reader *r = NULL;
    cdem_error err;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    snprintf(stop, cap, "%s", cdem_h5_reader_stop_reason(r));
    *n = cdem_h5_reader_increment_count(r);
    cdem_h5_reader_close(r);
}

/* --force over a completed run, and the new run killed: the completed run is still there,
 * as NAME.replaced, until the new run completes (issue 35, item 5: killing the new run 3 s in
 * left a 49-increment partial and the 284-increment run gone). A second --force over the
 * partial keeps it; the completed resumed run removes it. */
static void test_resume_force_keeps_the_replaced_run_until_done(void **state) {
    const rs_ctx *c = *state;
    assert_int_equal(run(c, NULL, "-q -o forced.h5 " SMALL), 0);
    char p[1200], aside[1300], stop[64];
    path_of(c, "forced.h5", p, sizeof p);
    snprintf(aside, sizeof aside, "%s.replaced", p);
    size_t done = 0, n = 0;
    stop_and_count(p, stop, sizeof stop, &done);
    assert_string_equal(stop, "completed");
    int st = start_and_signal_force(c, "forced", SIGKILL, 1);
    assert_true(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
    char log[1200];
    path_of(c, "forced.log", log, sizeof log);
    assert_true(file_has(log, "is kept as"));
    assert_true(file_has(log, "forced.h5.replaced until this run completes"));
    stop_and_count(aside, stop, sizeof stop, &n);
    assert_string_equal(stop, "completed");
    assert_int_equal(n, done);
    stop_and_count(p, stop, sizeof stop, &n);
    assert_string_equal(stop, "running"); /* the killed replacement */
    assert_true(n < done);
    /* --force again, over the killed partial: the completed run stays aside */
    st = start_and_signal_force(c, "forced", SIGKILL, 1);
    assert_true(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
    stop_and_count(aside, stop, sizeof stop, &n);
    assert_string_equal(stop, "completed");
    assert_int_equal(n, done);
    /* the replacement resumed to its end: now it stands in for the old run */
    assert_int_equal(run(c, NULL, "--resume forced.h5"), 0);
    expect_err(c, "removed ");
    expect_err(c, "forced.h5.replaced, the run this one replaced");
    assert_int_equal(access(aside, F_OK), -1);
    stop_and_count(p, stop, sizeof stop, &n);
    assert_string_equal(stop, "completed");
    assert_int_equal(n, done);
}

/* A killed run's file with one byte of a kept increment's data changed: the resume is refused
 * naming that increment, and the file is left byte for byte as it was (issue 35, item 4:
 * --resume reported "completed" over it, and `compute` failed its checksum later). */
static void test_resume_refuses_a_damaged_kept_increment(void **state) {
    const rs_ctx *c = *state;
    int st = start_and_signal(c, "damaged", SIGKILL);
    assert_true(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
    char p[1200], copy[1300], cmd[3000];
    path_of(c, "damaged.h5", p, sizeof p);
    snprintf(copy, sizeof copy, "%s.before", p);
    /* increment 1 starts at row 4096 of /increments/x: chunk 1 */
    const long at = chunk_at(p, "increments/x", 1);
    FILE *f = fopen(p, "r+b");
    assert_non_null(f);
    assert_int_equal(fseek(f, at, SEEK_SET), 0);
    int byte = fgetc(f);
    assert_int_equal(fseek(f, at, SEEK_SET), 0);
    fputc(byte ^ 0x01, f);
    assert_int_equal(fclose(f), 0);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", p, copy);
    assert_int_equal(system(cmd), 0);
    assert_int_equal(run(c, NULL, "-q --resume damaged.h5"), 1);
    expect_err(c, "damaged.h5: cannot be resumed: increment 1 does not read back");
    expect_err(c, "it was not changed");
    expect_err(c, "increments 0..0 read back");
    snprintf(cmd, sizeof cmd, "cmp -s '%s' '%s'", p, copy);
    assert_int_equal(system(cmd), 0);
}

/* A killed run's file cut short afterwards (a full disk, an interrupted copy): the resume is
 * refused saying so, and the file is left as it was. Once the message asked "is its writer
 * still running?" (issue 19, item 7); the writer's lock now tells that no writer runs. */
static void test_resume_truncated_killed_file(void **state) {
    const rs_ctx *c = *state;
    int st = start_and_signal(c, "cut", SIGKILL);
    assert_true(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
    char p[1200];
    path_of(c, "cut.h5", p, sizeof p);
    struct stat sb;
    assert_int_equal(stat(p, &sb), 0);
    const off_t cut = sb.st_size * 9 / 10;
    assert_int_equal(truncate(p, cut), 0);
    assert_int_equal(run(c, NULL, "-q --resume cut.h5"), 1);
    expect_err(c, "cut.h5: cannot be resumed: ");
    expect_err(c, "the file is truncated");
    expect_err(c, "it was not changed");
    char *e = slurp(c, "err.txt");
    assert_null(strstr(e, "still running"));
    free(e);
    assert_int_equal(stat(p, &sb), 0);
    assert_int_equal(sb.st_size, cut);
}

/* A resume of a run that is still being written is refused at once, naming the writer. */
static void test_resume_refused_while_running(void **state) {
    const rs_ctx *c = *state;
    char log[1200], out[1200];
    path_of(c, "live.log", log, sizeof log);
    path_of(c, "live.h5", out, sizeof out);
    fflush(NULL);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        FILE *f = freopen(log, "wb", stderr);
        if (!f || chdir(c->scratch.dir) != 0)
            _exit(99);
        execl(c->bin, c->bin, "-o", out, "-s", "output.checkpoint_interval=2", "-s",
              "assembly.width=10", "-s", "assembly.height=2.5", "-s", "time.equilibration=100",
              "-s", "time.runtime=600", (char *)NULL);
        _exit(98);
    }
    for (int i = 0; i < 60000 && !file_has(log, "end of equilibration"); i++) {
        const struct timespec ts = {0, 5000000};
        nanosleep(&ts, NULL);
    }
    int rc = run(c, NULL, "-q --resume live.h5");
    int st = 0;
    int ended = waitpid(pid, &st, WNOHANG) == pid;
    if (!ended) {
        kill(pid, SIGINT);
        assert_int_equal(waitpid(pid, &st, 0), pid);
    }
    if (ended)
        fail_msg("the run ended before its resume was tried; the test needs a longer run");
    assert_int_equal(rc, 1);
    char who[64];
    snprintf(who, sizeof who, "pid %d", (int)pid);
    expect_err(c, "live.h5 is being written by another process");
    expect_err(c, who);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_resume_determinism_threads_1_2_3),
        cmocka_unit_test(test_resume_after_sigkill_is_bit_identical),
        cmocka_unit_test(test_resume_after_max_steps_is_bit_identical),
        cmocka_unit_test(test_resume_salt_is_bit_identical),
        cmocka_unit_test(test_resume_refusals),
        cmocka_unit_test(test_resume_after_file_size_limit_is_bit_identical),
        cmocka_unit_test(test_resume_refuses_a_damaged_kept_increment),
        cmocka_unit_test(test_resume_torn_index_evidence),
        cmocka_unit_test(test_resume_force_keeps_the_replaced_run_until_done),
        cmocka_unit_test(test_resume_truncated_killed_file),
        cmocka_unit_test(test_resume_refused_while_running),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
