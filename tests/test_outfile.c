/* common/outfile: an output appears complete or not at all. Round trip (written through
 * <path>.tmp, renamed on success), failure (the temporary removed, an existing file left
 * as it was, the writer's status passed through), a stale temporary cleared, the up-front
 * refusals naming the path, and mkdir -p for folder outputs. Files in a private scratch
 * folder. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "outfile.h"
#include "scratch.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static void put(const char *path, const char *text) {
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* 1 when path holds exactly text. */
static int holds(const char *path, const char *text) {
    char buf[256] = "";
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return strcmp(buf, text) == 0;
}

static void test_outfile_success_renames(void **state) {
    const scratch_dir *d = *state;
    char path[1200];
    scratch_dir_path(d, path, sizeof path, "out.csv");
    put(path, "old\n"); /* replaced only when the new file is complete */
    cdem_outfile o;
    cdem_error err;
    assert_int_equal(cdem_outfile_begin(&o, path, &err), CDEM_OK);
    assert_string_equal(o.path, path);
    char tmp[1300];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    assert_string_equal(o.tmp, tmp);
    put(o.tmp, "new\n");
    assert_true(holds(path, "old\n")); /* not yet */
    assert_int_equal(cdem_outfile_end(&o, CDEM_OK, &err), CDEM_OK);
    assert_true(holds(path, "new\n"));
    assert_int_equal(access(tmp, F_OK), -1);
    assert_int_equal(o.active, 0);
}

static void test_outfile_failure_keeps_old_file(void **state) {
    const scratch_dir *d = *state;
    char path[1200];
    scratch_dir_path(d, path, sizeof path, "kept.csv");
    put(path, "old\n");
    cdem_outfile o;
    cdem_error err;
    assert_int_equal(cdem_outfile_begin(&o, path, &err), CDEM_OK);
    put(o.tmp, "half a fil");
    /* the writer's own status comes back unchanged; the temporary goes */
    assert_int_equal(cdem_outfile_end(&o, CDEM_ERR_NOMEM, &err), CDEM_ERR_NOMEM);
    assert_int_equal(access(o.tmp, F_OK), -1);
    assert_true(holds(path, "old\n"));
    /* discard does the same for a write abandoned without end; NULL is accepted */
    assert_int_equal(cdem_outfile_begin(&o, path, &err), CDEM_OK);
    put(o.tmp, "x");
    cdem_outfile_discard(&o);
    assert_int_equal(access(o.tmp, F_OK), -1);
    cdem_outfile_discard(NULL);
    /* end without begin */
    cdem_outfile idle = {0};
    assert_int_equal(cdem_outfile_end(&idle, CDEM_OK, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "not begun"));
}

static void test_outfile_stale_temporary_removed(void **state) {
    const scratch_dir *d = *state;
    char path[1200], tmp[1300];
    scratch_dir_path(d, path, sizeof path, "stale.png");
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    put(tmp, "left by a crash");
    cdem_outfile o;
    cdem_error err;
    assert_int_equal(cdem_outfile_begin(&o, path, &err), CDEM_OK);
    assert_int_equal(access(tmp, F_OK), -1);
    cdem_outfile_discard(&o);
}

static void test_outfile_refusals(void **state) {
    const scratch_dir *d = *state;
    cdem_outfile o;
    cdem_error err;
    char path[1300], want[4000];
    assert_int_equal(cdem_outfile_begin(&o, "", &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "output path is empty"));
    assert_int_equal(cdem_outfile_begin(&o, NULL, &err), CDEM_ERR_INVALID);
    static char long_path[CDEM_OUTFILE_PATH_MAX + 10];
    memset(long_path, 'a', sizeof long_path - 1);
    assert_int_equal(cdem_outfile_begin(&o, long_path, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "characters long; at most 4095 allowed"));
    /* a folder */
    assert_int_equal(cdem_outfile_begin(&o, d->dir, &err), CDEM_ERR_IO);
    snprintf(want, sizeof want, "cannot create %s: it is a folder", d->dir);
    assert_non_null(strstr(err.msg, want));
    /* a missing folder */
    scratch_dir_path(d, path, sizeof path, "no-such-folder/out.csv");
    assert_int_equal(cdem_outfile_begin(&o, path, &err), CDEM_ERR_IO);
    snprintf(want, sizeof want, "cannot create %s: folder %s/no-such-folder", path, d->dir);
    assert_non_null(strstr(err.msg, want));
    /* a "folder" that is a file */
    char file[1100];
    scratch_dir_path(d, file, sizeof file, "plain");
    put(file, "x");
    snprintf(path, sizeof path, "%s/out.csv", file);
    assert_int_equal(cdem_outfile_begin(&o, path, &err), CDEM_ERR_IO);
    snprintf(want, sizeof want, "cannot create %s: %s is not a folder", path, file);
    assert_non_null(strstr(err.msg, want));
}

static void test_outfile_make_dirs(void **state) {
    const scratch_dir *d = *state;
    char dir[1200];
    scratch_dir_path(d, dir, sizeof dir, "a/b/c");
    cdem_error err;
    assert_int_equal(cdem_outfile_make_dirs(dir, &err), CDEM_OK);
    struct stat sb;
    assert_int_equal(stat(dir, &sb), 0);
    assert_true(S_ISDIR(sb.st_mode));
    assert_int_equal(cdem_outfile_make_dirs(dir, &err), CDEM_OK); /* existing: fine */
    /* a file in the way is refused, naming it */
    char file[1200], below[1300];
    scratch_dir_path(d, file, sizeof file, "a/file");
    put(file, "x");
    snprintf(below, sizeof below, "%s/sub", file);
    assert_int_equal(cdem_outfile_make_dirs(below, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, file));
    assert_int_equal(cdem_outfile_make_dirs("", &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "output folder name is empty"));
}

/* The folder of a path: before the last '/', "/" at the root, "." without a '/'. */
static void test_outfile_folder_of(void **state) {
    (void)state;
    char buf[64];
    cdem_outfile_folder_of("out/runs/a.h5", buf, sizeof buf);
    assert_string_equal(buf, "out/runs");
    cdem_outfile_folder_of("/a.h5", buf, sizeof buf);
    assert_string_equal(buf, "/");
    cdem_outfile_folder_of("a.h5", buf, sizeof buf);
    assert_string_equal(buf, ".");
    cdem_outfile_folder_of("/tmp/x/", buf, sizeof buf);
    assert_string_equal(buf, "/tmp/x");
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_outfile_success_renames),
        cmocka_unit_test(test_outfile_failure_keeps_old_file),
        cmocka_unit_test(test_outfile_stale_temporary_removed),
        cmocka_unit_test(test_outfile_refusals),
        cmocka_unit_test(test_outfile_make_dirs),
        cmocka_unit_test(test_outfile_folder_of),
    };
    return cmocka_run_group_tests(tests, scratch_setup, scratch_teardown);
}
