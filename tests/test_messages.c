/* test_messages: three messages that said the wrong thing (issue 35, item 10).
 *  - A read-only file system got free-space advice ("free some space ... or
 *    --ignore-free-space"): the free-space check names a folder that cannot be written as such.
 *    Tested on a tmpfs mounted read-only in a private mount namespace (root, or an
 *    unprivileged user namespace), and on a folder of mode 0555 as a user who cannot write it
 *    (root can: access() says so); skipped, saying why, where neither can be set up.
 *  - "duplicate element id 7 at slots 0 and 1" named no file or increment: the reader refuses
 *    an id twice in an increment naming both, and the analysis prefixes what the state code
 *    says with the run and the increments.
 *  - A damaged index gave "analysis: the run has no increments": the message says what is
 *    wrong and names the file.
 *  - A folder given as a run file said "not a regular file" (issue 46, item 13c): it says it
 *    is a folder, and for a cdem2D folder how to import it.
 * Files go to a scratch folder; cdem-run and cdem-strain come from $CDEM_BUILD. */
#define _GNU_SOURCE /* unshare, CLONE_NEWNS, CLONE_NEWUSER */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "analysis.h"
#include "h5format.h"
#include "scratch.h"

#include <hdf5.h>

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static scratch_dir g_dir;
static char g_strain[1100], g_run[1100];

static int setup(void **state) {
    (void)state;
    if (scratch_dir_make(&g_dir, "messages") != 0)
        return -1;
    const char *b = getenv("CDEM_BUILD");
    char build[1024];
    if (!realpath(b && *b ? b : "build", build))
        return -1;
    snprintf(g_strain, sizeof g_strain, "%s/cdem-strain", build);
    snprintf(g_run, sizeof g_run, "%s/cdem-run", build);
    return 0;
}

static int teardown(void **state) {
    (void)state;
    return scratch_dir_remove(&g_dir);
}

/* Runs cmd (2>&1) in the scratch folder; its exit status, its output in out. */
static int run(char *out, size_t cap, const char *fmt, ...) {
    char cmd[4096], full[5200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    snprintf(full, sizeof full, "cd '%s' && %s 2>&1", g_dir.dir, cmd);
    FILE *p = popen(full, "r");
    assert_non_null(p);
    const size_t got = fread(out, 1, cap - 1, p);
    out[got] = '\0';
    while (fread(full, 1, sizeof full, p) > 0) {
    }
    const int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

#define HAS(out, text)                                                                             \
    do {                                                                                           \
        if (!strstr((out), (text)))                                                                \
            fail_msg("missing \"%s\" in:\n%s", (text), (out));                                     \
    } while (0)

/* ------------------------------------------------------------------ read-only folders */

/* In a child: a private mount namespace (as root; else as root of a new user namespace),
 * where a 64 KiB tmpfs is mounted read-only at dir. 0, or -1 when it cannot be done here. */
static int mount_read_only(const char *dir) {
    if (unshare(CLONE_NEWNS) != 0) {
        const uid_t uid = getuid();
        const gid_t gid = getgid();
        if (unshare(CLONE_NEWUSER | CLONE_NEWNS) != 0)
            return -1;
        char map[64];
        int fd = open("/proc/self/setgroups", O_WRONLY);
        if (fd >= 0) {
            (void)!write(fd, "deny", 4);
            close(fd);
        }
        snprintf(map, sizeof map, "0 %d 1", (int)uid);
        fd = open("/proc/self/uid_map", O_WRONLY);
        if (fd < 0 || write(fd, map, strlen(map)) < 0)
            return -1;
        close(fd);
        snprintf(map, sizeof map, "0 %d 1", (int)gid);
        fd = open("/proc/self/gid_map", O_WRONLY);
        if (fd < 0 || write(fd, map, strlen(map)) < 0)
            return -1;
        close(fd);
    }
    if (mount(NULL, "/", NULL, MS_REC | MS_PRIVATE, NULL) != 0) /* nothing leaks out */
        return -1;
    return mount("tmpfs", dir, "tmpfs", MS_RDONLY, "size=64k") == 0 ? 0 : -1;
}

/* The checks of a child, reported by its exit status: 0 held, 77 could not be set up, else
 * the number of the check that failed (its message on stderr). */
static int child_read_only(const char *dir) {
    if (mount_read_only(dir) != 0) {
        fprintf(stderr, "cannot mount a read-only tmpfs here: %s\n", strerror(errno));
        return 77;
    }
    char path[1300], out[1400];
    snprintf(path, sizeof path, "%s/run.h5", dir);
    cdem_error err;
    cdem_error_clear(&err);
    /* 8 MB in a 64 KiB file system: short of space too, but it is read-only that matters */
    const cdem_status st = cdem_h5_check_free_space(path, 8e6, &err);
    if (st == CDEM_ERR_IO || !strstr(err.msg, "is on a read-only file system") ||
        strstr(err.msg, "free")) {
        fprintf(stderr, "check 1: status %d: %s\n", (int)st, err.msg);
        return 1;
    }
    /* the program: its whole message */
    snprintf(out, sizeof out, "%s.log", dir);
    char cmd[4000];
    snprintf(cmd, sizeof cmd,
             "OMP_NUM_THREADS=1 %s -q -o %s -s assembly.width=10 -s assembly.height=2.5 > %s 2>&1",
             g_run, path, out);
    const int rc = system(cmd);
    FILE *f = fopen(out, "r");
    char text[4096] = "";
    if (f) {
        text[fread(text, 1, sizeof text - 1, f)] = '\0';
        fclose(f);
    }
    if (!WIFEXITED(rc) || WEXITSTATUS(rc) != 1 || !strstr(text, "read-only file system") ||
        strstr(text, "free some space") || strstr(text, "--ignore-free-space")) {
        fprintf(stderr, "check 2: cdem-run exit %d: %s\n", WIFEXITED(rc) ? WEXITSTATUS(rc) : -1,
                text);
        return 2;
    }
    return 0;
}

static int child_status(pid_t pid) {
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_true(WIFEXITED(status));
    return WEXITSTATUS(status);
}

static void test_messages_read_only_folder(void **state) {
    (void)state;
    char dir[1200];
    scratch_dir_path(&g_dir, dir, sizeof dir, "ro");
    assert_int_equal(mkdir(dir, 0755), 0);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0)
        _exit(child_read_only(dir));
    const int ro = child_status(pid);
    if (ro == 77)
        fprintf(stderr, "test_messages_read_only_folder: no read-only file system could be "
                        "mounted here (no mount namespace): that part was skipped\n");
    else
        assert_int_equal(ro, 0);
    /* a folder of mode 0555: root writes there anyway (access() agrees); another user does
     * not, and is told so instead of being told to free space */
    char open_dir[] = "/tmp/cdem_messages_XXXXXX";
    assert_non_null(mkdtemp(open_dir));
    assert_int_equal(chmod(open_dir, 0555), 0);
    char path[1200];
    snprintf(path, sizeof path, "%s/run.h5", open_dir);
    fflush(NULL);
    pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        if (getuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0))
            _exit(77);
        cdem_error err;
        cdem_error_clear(&err);
        const cdem_status st = cdem_h5_check_free_space(path, 1e18, &err);
        if (st == CDEM_ERR_IO || !strstr(err.msg, "is not writable") || strstr(err.msg, "free")) {
            fprintf(stderr, "status %d: %s\n", (int)st, err.msg);
            _exit(1);
        }
        _exit(0);
    }
    const int rw = child_status(pid);
    chmod(open_dir, 0755);
    rmdir(open_dir);
    if (rw == 77)
        fprintf(stderr, "test_messages_read_only_folder: cannot become another user: the 0555 "
                        "part was skipped\n");
    else
        assert_int_equal(rw, 0);
    if (ro == 77 && rw == 77)
        skip();
}

/* ------------------------------------------------------------------ duplicate ids */

static void write_run(const char *path, int increments, const char *reason) {
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "", "summary", "0", "cdem-run", 0};
    cdem_h5_writer *w = NULL;
    cdem_error err;
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    for (int k = 0; k < increments; k++) {
        cdem_state s = {0};
        cdem_state_init(&s, 20, 0, &err);
        for (int i = 0; i < 20; i++)
            cdem_state_append(&s, i, 120.0 * (i % 5) + k, 120.0 * (i / 5), 50.0, 1.0, 1, 0, 0, NULL,
                              &err);
        cdem_increment_info in = {.number = k, .step = 10 * k, .time = k, .sea_level = NAN};
        in.phase = k < 1 ? CDEM_PHASE_EQUILIBRATION : CDEM_PHASE_DEFORMATION;
        assert_int_equal(cdem_h5_writer_write_increment(w, &in, &s, &err), CDEM_OK);
        cdem_state_free(&s);
    }
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, reason, "detail", &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
}

static void test_messages_duplicate_id(void **state) {
    (void)state;
    char path[1200], out[1 << 14];
    scratch_dir_path(&g_dir, path, sizeof path, "dup.h5");
    write_run(path, 3, "completed");
    /* id 7 twice in increment 2 (row 1 takes row 7's id), as an edited file can have it */
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t ds = H5Dopen2(f, "increments/id", H5P_DEFAULT);
    hsize_t row = 2 * 4096 + 1, one = 1;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(1, &one, NULL);
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &row, NULL, &one, NULL);
    const int32_t seven = 7;
    assert_true(H5Dwrite(ds, H5T_NATIVE_INT32, ms, fs, H5P_DEFAULT, &seven) >= 0);
    H5Sclose(ms);
    H5Sclose(fs);
    H5Dclose(ds);
    H5Fclose(f);
    assert_int_equal(
        run(out, sizeof out, "%s compute dup.h5 --increment 2 --quantity incr-e1", g_strain), 1);
    HAS(out, "dup.h5: increment 2: element id 7 appears twice, at /increments/id row 8193 and at "
             "row 8199");
    /* the analysis of states (no file to refuse them): the run and the increments named */
    enum { N = 2 };
    cdem_state st[N];
    cdem_increment_info in[N];
    cdem_error err;
    for (int k = 0; k < N; k++) {
        memset(&st[k], 0, sizeof st[k]);
        cdem_state_init(&st[k], 20, 0, &err);
        for (int i = 0; i < 20; i++)
            cdem_state_append(&st[k], i == 1 ? 7 : i, 120.0 * (i % 5) + k, 120.0 * (i / 5), 50.0,
                              1.0, 1, 0, 0, NULL, &err);
        in[k] = (cdem_increment_info){.number = 3 * k, .phase = k, .sea_level = NAN};
    }
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_analysis *a = NULL;
    assert_int_equal(cdem_analysis_open_states(st, in, N, &p, &a, &err), CDEM_OK);
    cdem_analysis_set_name(a, "states.h5");
    const cdem_quantity *q = NULL;
    assert_int_equal(cdem_quantity_find("incr-disp-x", &q, &err), CDEM_OK);
    const cdem_state *s = NULL;
    double *v = NULL;
    assert_int_not_equal(cdem_analysis_values(a, 1, q, &s, &v, &err), CDEM_OK);
    HAS(err.msg, "states.h5: increment 3 against increment 0: duplicate element id 7");
    assert_int_equal(cdem_quantity_find("total-e1", &q, &err), CDEM_OK);
    assert_int_not_equal(cdem_analysis_values(a, 1, q, &s, &v, &err), CDEM_OK);
    HAS(err.msg, "states.h5: increment 3 against increment 0: duplicate element id 7");
    cdem_axes ax;
    assert_int_not_equal(cdem_analysis_axes(a, 1, CDEM_AXES_INCR_STRAIN, &ax, &err), CDEM_OK);
    HAS(err.msg, "states.h5: increment 3 against increment 0: duplicate element id 7");
    cdem_analysis_close(a);
    for (int k = 0; k < N; k++)
        cdem_state_free(&st[k]);
}

/* ------------------------------------------------------------------ no increments */

static void test_messages_no_increments(void **state) {
    (void)state;
    char path[1200], out[1 << 14];
    /* an old-layout file (no commit record) whose index was replaced by a 5 x 5 float
     * dataset: the audit's "analysis: the run has no increments" */
    scratch_dir_path(&g_dir, path, sizeof path, "index.h5");
    write_run(path, 3, "completed");
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(H5Ldelete(f, "increments/commit", H5P_DEFAULT) >= 0);
    assert_true(H5Ldelete(f, "increments/index", H5P_DEFAULT) >= 0);
    hsize_t dims[2] = {5, 5};
    hid_t sp = H5Screate_simple(2, dims, NULL);
    hid_t ds = H5Dcreate2(f, "increments/index", H5T_IEEE_F64LE, sp, H5P_DEFAULT, H5P_DEFAULT,
                          H5P_DEFAULT);
    H5Dclose(ds);
    H5Sclose(sp);
    H5Fclose(f);
    const char *commands[] = {"compute index.h5 --increment last --quantity incr-e1",
                              "info index.h5", "render index.h5 -o x.png"};
    for (size_t c = 0; c < 3; c++) {
        assert_int_equal(run(out, sizeof out, "%s %s", g_strain, commands[c]), 1);
        HAS(out, "index.h5: dataset /increments/index (the list of increments) is a 2-D float "
                 "dataset, not the 1-D compound dataset of index rows");
        assert_null(strstr(out, "has no increments"));
    }
    /* a commit record blanked in a closed file: the index's length names it */
    scratch_dir_path(&g_dir, path, sizeof path, "blank.h5");
    write_run(path, 3, "completed");
    f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    ds = H5Dopen2(f, "increments/commit", H5P_DEFAULT);
    hid_t ft = H5Dget_type(ds);
    void *zeros = calloc(3, H5Tget_size(ft));
    hsize_t three = 3, zero = 0;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(1, &three, NULL);
    H5Sselect_hyperslab(fs, H5S_SELECT_SET, &zero, NULL, &three, NULL);
    assert_true(H5Dwrite(ds, ft, ms, fs, H5P_DEFAULT, zeros) >= 0);
    free(zeros);
    H5Sclose(ms);
    H5Sclose(fs);
    H5Tclose(ft);
    H5Dclose(ds);
    H5Fclose(f);
    assert_int_equal(
        run(out, sizeof out, "%s compute blank.h5 --increment last --quantity incr-e1", g_strain),
        1);
    HAS(out, "blank.h5: the commit record /increments/commit holds 0 committed rows but "
             "/increments/index 3");
    /* files that truly hold none: what happened to the run */
    scratch_dir_path(&g_dir, path, sizeof path, "failed.h5");
    write_run(path, 0, "error");
    assert_int_equal(
        run(out, sizeof out, "%s compute failed.h5 --increment last --quantity incr-e1", g_strain),
        1);
    HAS(out, "failed.h5: the file holds no increment: the run stopped (stop reason \"error\": "
             "detail) before writing increment 0");
    scratch_dir_path(&g_dir, path, sizeof path, "killed.h5");
    fflush(NULL);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        cdem_params p;
        cdem_params_defaults(&p);
        cdem_run_meta meta = {&p, "", "summary", "0", "cdem-run", 0};
        cdem_h5_writer *w = NULL;
        cdem_error err;
        _exit(cdem_h5_writer_create(path, &meta, &w, &err) == CDEM_OK ? 0 : 2); /* not closed */
    }
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid && WIFEXITED(status) && !WEXITSTATUS(status));
    assert_int_equal(
        run(out, sizeof out, "%s compute killed.h5 --increment last --quantity incr-e1", g_strain),
        1);
    HAS(out, "killed.h5: the file holds no increment: its writer stopped before writing increment "
             "0 (killed or crashed; no writer holds the file)");
}

/* ------------------------------------------------------------------ a folder */

/* A folder given as a run file (issue 46, item 13c: "not a regular file" for a cdem2D
 * folder, without a word of import-cdem2d): the message says it is a folder and, for a
 * cdem2D simulation folder, gives the import command. */
static void test_messages_folder_given_as_run(void **state) {
    (void)state;
    char out[1 << 14], dir[1200];
    const char *data = getenv("CDEM_TEST_DATA");
    if (!realpath(data && *data ? data : "tests/data", dir))
        fail_msg("no tests/data");
    static const char *const commands[][2] = {
        {"info", ""}, {"compute", " --increment last --quantity incr-e1"}, {"render", " -o x.png"}};
    for (size_t c = 0; c < 3; c++) {
        assert_int_equal(run(out, sizeof out, "%s %s '%s/cdem2d_basic'%s", g_strain, commands[c][0],
                             dir, commands[c][1]),
                         1);
        HAS(out, "/cdem2d_basic: is a folder, not a cdem run file; it holds modelresults_N.txt "
                 "files, so it looks like a cdem2D simulation folder: import it with "
                 "`cdem-strain import-cdem2d ");
        HAS(out, "/cdem2d_basic -o run.h5` and read run.h5");
        assert_null(strstr(out, "not a regular file"));
    }
    /* any other folder: a folder, and no import advice */
    assert_int_equal(run(out, sizeof out, "mkdir -p plain && %s info plain", g_strain), 1);
    HAS(out, "plain: is a folder, not a cdem run file (the HDF5 file cdem-run writes)");
    assert_null(strstr(out, "import-cdem2d"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_messages_read_only_folder),
        cmocka_unit_test(test_messages_duplicate_id),
        cmocka_unit_test(test_messages_no_increments),
        cmocka_unit_test(test_messages_folder_given_as_run),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
