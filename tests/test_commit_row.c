/* One damaged row of the commit record, /increments/commit (issue 46, item 1; docs/format.md,
 * "/increments/commit"; docs/reliability.md, "Damaged files"). Once, one flipped byte in any
 * row, even a spare row never written, made every increment of the file unreadable
 * ("rows 0..29 are valid: damaged file", and "rows 0..-1" for row 0). Now, for a completed
 * run's file and for a killed run's file, a byte of EACH row (every written row and every
 * spare row) is flipped in turn, and:
 *  - the file opens; its damage text (the warning the reader writes to stderr) names the row
 *    and says whether an increment is lost;
 *  - every other increment reads back identical to the undamaged file, before and after the
 *    damaged row (each valid row proves itself by its own checksum);
 *  - the damaged row's increment is refused by number (and "last" when it is the last row),
 *    the message naming the row and saying it is damaged;
 *  - in the killed file the first spare row may be the row a kill tore: when it crosses a page
 *    boundary a flipped byte there cannot be told from a tear and is left out silently, as a
 *    torn row is; a row that crosses none cannot be torn, so a flip there is damage.
 * cdem-strain info and compute are run on a written and a spare damaged row (one warning on
 * stderr, the refusal naming the row), and cdem-run --resume on the killed file with its
 * checkpoint's row damaged (it resumes from the older checkpoint, before that row, and ends
 * with the uninterrupted run's file), with row 0 damaged (refused: no checkpoint precedes it,
 * the file unchanged) and with a spare row damaged (resumed, identical).
 * Scratch files go to a private directory under $CDEM_TEST_TMP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "h5format.h"
#include "scratch.h"

#include <hdf5.h>

#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* A small model (1370 elements, 22 increments), a checkpoint every 2 increments. */
static const char *const model_args[] = {
    "-s", "output.checkpoint_interval=2",
    "-s", "assembly.width=10",
    "-s", "assembly.height=2.5",
    "-s", "time.equilibration=100",
    "-s", "time.runtime=150",
    "-s", "output.series_interval=50",
    "-s", "physics.calculate_stress=on",
};
enum { N_MODEL_ARGS = sizeof model_args / sizeof model_args[0] };
enum { ROW_BYTES = 92 }; /* a commit row in the file (docs/format.md) */

typedef struct {
    char run[1024], strain[1024]; /* cdem-run, cdem-strain */
    scratch_dir scratch;
    char done[1200];   /* the completed run (checkpoints kept) */
    char killed[1200]; /* the same run SIGKILLed after its equilibration */
} cr_ctx;

static void bin_path(char *buf, size_t cap, const char *name) {
    const char *b = getenv("CDEM_BUILD");
    char rel[1024];
    snprintf(rel, sizeof rel, "%s/%s", b && b[0] ? b : "build", name);
    if (!realpath(rel, buf))
        snprintf(buf, cap, "%s", rel);
}

static void path_of(const cr_ctx *c, const char *name, char *buf, size_t cap) {
    snprintf(buf, cap, "%s/%s", c->scratch.dir, name);
}

static char *slurp(const char *path) {
    FILE *f = fopen(path, "rb");
    char *buf = calloc(1, 1 << 16);
    assert_non_null(buf);
    if (f) {
        size_t n = fread(buf, 1, (1 << 16) - 1, f);
        buf[n] = '\0';
        fclose(f);
    }
    return buf;
}

/* Runs cdem-run with args (NULL-terminated), env KEEP set, stderr to log; wait status. With
 * kill_at_equil, SIGKILLs it once its log reports the end of equilibration. */
static int run_solver(const cr_ctx *c, const char *const *args, const char *log,
                      int kill_at_equil) {
    fflush(NULL);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        if (!freopen(log, "wb", stderr) || !freopen("/dev/null", "wb", stdout) ||
            chdir(c->scratch.dir) != 0)
            _exit(99);
        setenv("CDEM_KEEP_CHECKPOINTS", "1", 1);
        setenv("OMP_WAIT_POLICY", "passive", 1);
        char *argv[40];
        int k = 0;
        argv[k++] = (char *)c->run;
        for (; args[k - 1]; k++)
            argv[k] = (char *)args[k - 1];
        argv[k] = NULL;
        execv(c->run, argv);
        _exit(98);
    }
    int st = 0;
    for (int i = 0; kill_at_equil && i < 60000; i++) {
        if (waitpid(pid, &st, WNOHANG) == pid)
            fail_msg("cdem-run ended (status %d) before it could be killed", st);
        char *text = slurp(log);
        const int at = strstr(text, "end of equilibration") != NULL;
        free(text);
        if (at) {
            assert_int_equal(kill(pid, SIGKILL), 0);
            break;
        }
        const struct timespec ts = {0, 5000000};
        nanosleep(&ts, NULL);
    }
    assert_int_equal(waitpid(pid, &st, 0), pid);
    return st;
}

static int setup(void **state) {
    cr_ctx *c = calloc(1, sizeof *c);
    if (!c || scratch_dir_make(&c->scratch, "test_commit_row") != 0) {
        free(c);
        return -1;
    }
    bin_path(c->run, sizeof c->run, "cdem-run");
    bin_path(c->strain, sizeof c->strain, "cdem-strain");
    path_of(c, "done.h5", c->done, sizeof c->done);
    path_of(c, "killed.h5", c->killed, sizeof c->killed);
    *state = c;
    return 0;
}

static int teardown(void **state) {
    cr_ctx *c = *state;
    int rc = scratch_dir_remove(&c->scratch);
    free(c);
    return rc;
}

/* The runs every test uses, made once: the completed run and the killed one. */
static void make_runs(cr_ctx *c) {
    static const char *done_args[3 + N_MODEL_ARGS + 1] = {"-q", "-o", "done.h5"};
    static const char *killed_args[2 + N_MODEL_ARGS + 1] = {"-o", "killed.h5"};
    if (access(c->done, F_OK) == 0)
        return;
    for (size_t i = 0; i < N_MODEL_ARGS; i++)
        done_args[3 + i] = killed_args[2 + i] = model_args[i];
    char log[1200];
    path_of(c, "done.log", log, sizeof log);
    int st = run_solver(c, done_args, log, 0);
    assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    path_of(c, "killed.log", log, sizeof log);
    st = run_solver(c, killed_args, log, 1);
    assert_true(WIFSIGNALED(st) && WTERMSIG(st) == SIGKILL);
}

static void copy_file(const char *from, const char *to) {
    char cmd[3000];
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", from, to);
    assert_int_equal(system(cmd), 0);
}

/* The file offset of row 0 of the commit record and its rows (contiguous dataset). */
static void commit_record(const char *path, long *at, long *rows) {
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_file_locking(fapl, 0, 1);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    if (f < 0) { /* a killed writer's file: read as the reader does */
        hbool_t yes = 1;
        H5Pset(fapl, "clear_status_flags", &yes);
        f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    }
    H5Pclose(fapl);
    assert_true(f >= 0);
    hid_t ds = H5Dopen2(f, "increments/commit", H5P_DEFAULT);
    assert_true(ds >= 0);
    haddr_t addr = H5Dget_offset(ds);
    assert_true(addr != HADDR_UNDEF);
    hid_t sp = H5Dget_space(ds);
    hsize_t n = 0;
    H5Sget_simple_extent_dims(sp, &n, NULL);
    H5Sclose(sp);
    H5Dclose(ds);
    H5Fclose(f);
    *at = (long)addr;
    *rows = (long)n;
}

/* Flips bits of byte `byte` of commit row `row`. */
static void flip(const char *path, long at, long row, int byte) {
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    const long off = at + row * ROW_BYTES + byte;
    assert_int_equal(fseek(f, off, SEEK_SET), 0);
    int b = fgetc(f);
    assert_true(b != EOF);
    assert_int_equal(fseek(f, off, SEEK_SET), 0);
    fputc(b ^ 0x5a, f);
    assert_int_equal(fclose(f), 0);
}

static cdem_h5_reader *open_or_fail(const char *path) {
    cdem_h5_reader *r = NULL;
    cdem_error err;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s does not open: %s", path, err.msg);
    return r;
}

static void same_array(const void *a, const void *b, size_t n, size_t size, const char *what,
                       int inc, long row) {
    if ((a == NULL) != (b == NULL) || (a && memcmp(a, b, n * size) != 0))
        fail_msg("row %ld damaged: increment %d: %s differs from the undamaged file", row, inc,
                 what);
}

/* Increment number k of r and of the undamaged u are identical (info and every dataset). */
static void same_increment(cdem_h5_reader *r, cdem_h5_reader *u, int k, long row) {
    char spec[32];
    snprintf(spec, sizeof spec, "%d", k);
    size_t ir = 0, iu = 0;
    cdem_error err;
    if (cdem_h5_reader_find_increment(u, spec, &iu, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    if (cdem_h5_reader_find_increment(r, spec, &ir, &err) != CDEM_OK)
        fail_msg("row %ld damaged: increment %d is not found: %s", row, k, err.msg);
    cdem_state a = {0}, b = {0};
    cdem_increment_info ia, ib;
    if (cdem_h5_reader_load_increment(r, ir, &a, &ia, &err) != CDEM_OK)
        fail_msg("row %ld damaged: increment %d does not load: %s", row, k, err.msg);
    if (cdem_h5_reader_load_increment(u, iu, &b, &ib, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    if (memcmp(&ia, &ib, sizeof ia) != 0)
        fail_msg("row %ld damaged: increment %d: its index row differs", row, k);
    assert_int_equal(a.n, b.n);
    assert_int_equal(a.has_stress, b.has_stress);
    same_array(a.id, b.id, a.n, sizeof *a.id, "id", k, row);
    same_array(a.x, b.x, a.n, sizeof *a.x, "x", k, row);
    same_array(a.y, b.y, a.n, sizeof *a.y, "y", k, row);
    same_array(a.radius, b.radius, a.n, sizeof *a.radius, "radius", k, row);
    same_array(a.layer, b.layer, a.n, sizeof *a.layer, "layer", k, row);
    same_array(a.flags, b.flags, a.n, sizeof *a.flags, "flags", k, row);
    same_array(a.born, b.born, a.n, sizeof *a.born, "born", k, row);
    if (a.has_stress) {
        same_array(a.sxx, b.sxx, a.n, sizeof *a.sxx, "sxx", k, row);
        same_array(a.syy, b.syy, a.n, sizeof *a.syy, "syy", k, row);
        same_array(a.sxy, b.sxy, a.n, sizeof *a.sxy, "sxy", k, row);
    }
    cdem_state_free(&a);
    cdem_state_free(&b);
}

static void has(const char *text, const char *needle, long row) {
    if (!strstr(text, needle))
        fail_msg("row %ld damaged: \"%s\" lacks \"%s\"", row, text, needle);
}

/* Every row of path's commit record flipped in turn (a copy each time), checked as the file
 * comment says. unclosed: the file of a killed writer. */
static void flip_every_row(const cr_ctx *c, const char *pristine, int unclosed) {
    char path[1200];
    path_of(c, unclosed ? "flip_killed.h5" : "flip_done.h5", path, sizeof path);
    cdem_h5_reader *u = open_or_fail(pristine);
    assert_string_equal(cdem_h5_reader_damage(u), "");
    const int n = (int)cdem_h5_reader_increment_count(u);
    assert_true(n > 3);
    cdem_increment_info last;
    cdem_error err;
    assert_int_equal(cdem_h5_reader_increment_info(u, (size_t)n - 1, &last, &err), CDEM_OK);
    assert_int_equal(last.number, n - 1); /* cdem-run numbers its increments by row */
    long at = 0, capacity = 0;
    commit_record(pristine, &at, &capacity);
    assert_true(capacity > n);
    int silent = 0;
    for (long row = 0; row < capacity; row++) {
        copy_file(pristine, path);
        flip(path, at, row, (int)(row * 7 % ROW_BYTES));
        cdem_h5_reader *r = NULL;
        if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
            fail_msg("row %ld damaged: the file does not open: %s", row, err.msg);
        const char *d = cdem_h5_reader_damage(r);
        char needle[160];
        size_t index = 0;
        if (row < n) { /* a written row: its increment alone is lost */
            assert_int_equal(cdem_h5_reader_increment_count(r), (size_t)n - 1);
            snprintf(needle, sizeof needle, "/increments/commit row %ld (increment %ld)", row, row);
            has(d, needle, row);
            has(d, path, row);
            has(d, "damaged file", row);
            snprintf(needle, sizeof needle, "increment %ld cannot be read", row);
            has(d, needle, row);
            snprintf(needle, sizeof needle, "%ld", row);
            if (cdem_h5_reader_find_increment(r, needle, &index, &err) != CDEM_ERR_FORMAT)
                fail_msg("row %ld damaged: its increment is not refused", row);
            snprintf(needle, sizeof needle, "/increments/commit row %ld, is damaged", row);
            has(err.msg, needle, row);
            snprintf(needle, sizeof needle, "increment %ld cannot be read", row);
            has(err.msg, needle, row);
            const cdem_status st = cdem_h5_reader_find_increment(r, "last", &index, &err);
            if (row == n - 1) {
                assert_int_equal(st, CDEM_ERR_FORMAT);
                snprintf(needle, sizeof needle, "/increments/commit row %ld (increment %ld)", row,
                         row);
                has(err.msg, needle, row);
            } else {
                assert_int_equal(st, CDEM_OK);
            }
            int32_t through = 0;
            assert_int_equal(cdem_h5_reader_damaged_increments(r, &through), 1);
            assert_int_equal(through, row - 1);
        } else {
            const long first = at + row * ROW_BYTES, end = first + ROW_BYTES - 1;
            const int tearable = unclosed && row == n && first / 4096 != end / 4096;
            assert_int_equal(cdem_h5_reader_increment_count(r), (size_t)n);
            assert_int_equal(cdem_h5_reader_damaged_increments(r, NULL), 0);
            if (tearable) { /* cannot be told from the row a kill tore: left out, silent */
                assert_string_equal(d, "");
                silent++;
            } else {
                snprintf(needle, sizeof needle, "/increments/commit row %ld (a spare row)", row);
                has(d, needle, row);
                has(d, "no increment is lost", row);
            }
        }
        for (int k = 0; k < n; k++)
            if (k != row)
                same_increment(r, u, k, row);
        cdem_h5_reader_close(r);
    }
    cdem_h5_reader_close(u);
    printf("%s file: %d increments, %ld rows each flipped in turn (%d silent as a possible "
           "torn row)\n",
           unclosed ? "killed" : "completed", n, capacity, silent);
    remove(path);
}

static void test_commit_row_flipped_completed(void **state) {
    cr_ctx *c = *state;
    make_runs(c);
    flip_every_row(c, c->done, 0);
}

static void test_commit_row_flipped_killed(void **state) {
    cr_ctx *c = *state;
    make_runs(c);
    flip_every_row(c, c->killed, 1);
}

/* Runs a shell command line in the scratch folder, stdout and stderr to out.txt and err.txt;
 * its exit status. */
static int shell(const cr_ctx *c, const char *line) {
    char cmd[5000];
    snprintf(cmd, sizeof cmd, "cd '%s' && %s >'%s/out.txt' 2>'%s/err.txt'", c->scratch.dir, line,
             c->scratch.dir, c->scratch.dir);
    const int st = system(cmd);
    assert_true(WIFEXITED(st));
    return WEXITSTATUS(st);
}

static char *scratch_text(const cr_ctx *c, const char *name) {
    char p[1200];
    path_of(c, name, p, sizeof p);
    return slurp(p);
}

static int count_of(const char *text, const char *needle) {
    int n = 0;
    for (const char *p = strstr(text, needle); p; p = strstr(p + 1, needle))
        n++;
    return n;
}

/* The commands: one warning on stderr naming the file and the row; info says so on stdout
 * (and in --json); compute of the damaged increment fails naming the row, of another one
 * succeeds. The row 0 of a salt run said "rows 0..-1 are valid". */
static void test_commit_row_commands(void **state) {
    cr_ctx *c = *state;
    make_runs(c);
    char path[1200], line[3000];
    path_of(c, "cmd.h5", path, sizeof path);
    long at = 0, capacity = 0;
    commit_record(c->done, &at, &capacity);
    cdem_h5_reader *u = open_or_fail(c->done);
    const long n = (long)cdem_h5_reader_increment_count(u);
    cdem_h5_reader_close(u);
    const long rows[] = {0, 3, n - 1, n, capacity - 1};
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        const long row = rows[i];
        copy_file(c->done, path);
        flip(path, at, row, 13);
        char needle[200];
        snprintf(line, sizeof line, "'%s' info cmd.h5", c->strain);
        assert_int_equal(shell(c, line), 0);
        char *out = scratch_text(c, "out.txt"), *err = scratch_text(c, "err.txt");
        if (count_of(err, "warning: ") != 1)
            fail_msg("row %ld damaged: info: not one warning on stderr:\n%s", row, err);
        has(err, "cmd.h5: damaged file: /increments/commit row", row);
        snprintf(needle, sizeof needle, "row %ld (", row);
        has(err, needle, row);
        has(out, "\ndamaged: /increments/commit row", row);
        assert_null(strstr(err, "..-1"));
        free(out);
        free(err);
        snprintf(line, sizeof line, "'%s' info cmd.h5 --json", c->strain);
        assert_int_equal(shell(c, line), 0);
        out = scratch_text(c, "out.txt");
        has(out, "\"damage\": \"", row);
        free(out);
        snprintf(line, sizeof line,
                 "'%s' compute cmd.h5 --increment %ld --quantity total-max-shear -o c.csv",
                 c->strain, row);
        const int rc = shell(c, line);
        err = scratch_text(c, "err.txt");
        if (row < n) {
            if (rc != 1)
                fail_msg("row %ld damaged: compute of its increment: exit %d\n%s", row, rc, err);
            snprintf(needle, sizeof needle,
                     "increment %ld cannot be read: its row of the commit record, "
                     "/increments/commit row %ld, is damaged",
                     row, row);
            has(err, needle, row);
        } else {
            assert_int_equal(rc, 1); /* no such increment: the run has 0..n-1 */
            has(err, "does not exist", row);
        }
        free(err);
        snprintf(line, sizeof line,
                 "'%s' compute cmd.h5 --increment %ld --quantity total-max-shear -o c.csv",
                 c->strain, row == 1 ? 2L : 1L);
        if (shell(c, line) != 0) {
            err = scratch_text(c, "err.txt");
            fail_msg("row %ld damaged: compute of another increment failed:\n%s", row, err);
        }
    }
}

/* Every increment, the series, the texts of two files identical (creation time aside). */
static void same_files(const char *pa, const char *pb) {
    cdem_h5_reader *a = open_or_fail(pa), *b = open_or_fail(pb);
    assert_string_equal(cdem_h5_reader_stop_reason(a), cdem_h5_reader_stop_reason(b));
    assert_string_equal(cdem_h5_reader_damage(b), "");
    const size_t n = cdem_h5_reader_increment_count(a);
    assert_int_equal(n, cdem_h5_reader_increment_count(b));
    for (size_t k = 0; k < n; k++) {
        cdem_increment_info in;
        cdem_error err;
        assert_int_equal(cdem_h5_reader_increment_info(a, k, &in, &err), CDEM_OK);
        same_increment(b, a, in.number, -1);
    }
    cdem_series_sample *qa = NULL, *qb = NULL;
    size_t na = 0, nb = 0;
    cdem_error err;
    if (cdem_h5_reader_read_series(a, &qa, &na, &err) != CDEM_OK ||
        cdem_h5_reader_read_series(b, &qb, &nb, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    assert_int_equal(na, nb);
    assert_memory_equal(qa, qb, na * sizeof *qa);
    free(qa);
    free(qb);
    cdem_h5_reader_close(a);
    cdem_h5_reader_close(b);
}

/* --resume of the killed file never builds on a damaged row. */
static void test_commit_row_resume(void **state) {
    cr_ctx *c = *state;
    make_runs(c);
    char path[1200], copy[1300], line[3000], needle[3000];
    path_of(c, "res.h5", path, sizeof path);
    snprintf(copy, sizeof copy, "%s.before", path);
    long at = 0, capacity = 0;
    commit_record(c->killed, &at, &capacity);
    cdem_h5_reader *u = open_or_fail(c->killed);
    const long n = (long)cdem_h5_reader_increment_count(u);
    cdem_snapshot *snap = NULL;
    cdem_error err;
    int32_t newest = -1;
    assert_int_equal(cdem_snapshot_alloc(&snap, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_read_checkpoint(u, snap, &newest, &err), CDEM_OK);
    cdem_snapshot_free(snap);
    cdem_h5_reader_close(u);
    assert_true(newest >= 3 && newest < n);
    snprintf(line, sizeof line,
             "env CDEM_KEEP_CHECKPOINTS=1 OMP_WAIT_POLICY=passive '%s' -q --resume res.h5", c->run);

    /* the checkpoint's own row damaged: resumed from the older checkpoint, 2 increments
     * before, and the run ends as the uninterrupted one */
    copy_file(c->killed, path);
    flip(path, at, newest, 40);
    if (shell(c, line) != 0) {
        char *e = scratch_text(c, "err.txt");
        fail_msg("the resume with row %d damaged failed:\n%s", (int)newest, e);
    }
    char *e = scratch_text(c, "err.txt");
    snprintf(needle, sizeof needle,
             "resuming %s from the checkpoint of increment %d, before its damaged commit row "
             "(the newest checkpoint, of increment %d, follows that row)",
             "res.h5", (int)newest - 2, (int)newest);
    has(e, needle, newest);
    free(e);
    same_files(c->done, path);

    /* row 0 damaged: no checkpoint precedes it; refused, the file unchanged */
    copy_file(c->killed, path);
    flip(path, at, 0, 40);
    copy_file(path, copy);
    assert_int_equal(shell(c, line), 1);
    e = scratch_text(c, "err.txt");
    has(e, "res.h5: cannot be resumed: its checkpoint belongs to increment", 0);
    has(e, "after a damaged row of its commit record", 0);
    has(e, "/increments/commit row 0 (increment 0)", 0);
    has(e, "a resumed run would build on the damaged row; it was not changed", 0);
    free(e);
    snprintf(needle, sizeof needle, "cmp -s '%s' '%s'", path, copy);
    assert_int_equal(system(needle), 0);

    /* a spare row damaged (a row that cannot be torn): resumed from the newest checkpoint;
     * the resume blanks the row, and the run ends as the uninterrupted one */
    long spare = n + 1;
    while (spare < capacity &&
           (at + spare * ROW_BYTES) / 4096 != (at + spare * ROW_BYTES + 91) / 4096)
        spare++;
    assert_true(spare < capacity);
    copy_file(c->killed, path);
    flip(path, at, spare, 40);
    assert_int_equal(shell(c, line), 0);
    same_files(c->done, path);
    remove(copy);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_commit_row_flipped_completed),
        cmocka_unit_test(test_commit_row_flipped_killed),
        cmocka_unit_test(test_commit_row_commands),
        cmocka_unit_test(test_commit_row_resume),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
