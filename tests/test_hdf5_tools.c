/* Which HDF5 tools read a run file, and when (docs/format.md, first paragraph; issue 35: the
 * page said "any HDF5 tool" reads it, and h5ls cannot open a running or a killed file).
 * Checked with Debian's tools on a real run: while it runs, h5ls refuses the file and h5py
 * with swmr=True reads it; after a SIGKILL, h5ls still refuses it, h5py with swmr=True reads
 * it, and h5ls -r reads a copy after `h5clear -s` on the copy; once complete, h5ls reads
 * it. cdem-strain reads it every time (other tests). Runs from the repository root; the
 * programs in $CDEM_BUILD; scratch in $CDEM_TEST_TMP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scratch.h"

static char *slurp(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    if (buf)
        buf[n] = '\0';
    fclose(f);
    return buf;
}

/* The page says when other tools can read the file, not "any HDF5 tool". */
static void test_hdf5_tools_documented(void **unused) {
    (void)unused;
    char *page = slurp("docs/format.md");
    assert_non_null(page);
    char *end = strstr(page, "\n\n## ");
    assert_non_null(end);
    *end = '\0'; /* the introduction */
    assert_null(strstr(page, "any HDF5 tool read"));
    assert_non_null(strstr(page, "h5clear -s"));
    assert_non_null(strstr(page, "swmr=True"));
    free(page);
}

/* The tools on a running, a killed and a completed file. */
static void test_hdf5_tools_running_killed_completed(void **unused) {
    (void)unused;
    scratch_dir d;
    assert_int_equal(scratch_dir_make(&d, "test_hdf5_tools"), 0);
    const char *b = getenv("CDEM_BUILD");
    char cmd[8192];
    /* a default model with a long runtime: it runs for tens of seconds, and is killed
     * once the checks of a running file are done */
    snprintf(
        cmd, sizeof cmd,
        "cd '%s' && B='%s' && "
        "py() { /usr/bin/python3 -c \"import h5py, sys; "
        "f = h5py.File(sys.argv[1], 'r', swmr=sys.argv[2] == 'swmr'); "
        "print(sys.argv[1], 'h5py', sys.argv[2], len(f['increments/index']), 'rows')\" \"$@\"; }; "
        "OMP_WAIT_POLICY=passive $B/cdem-run -q -o run.h5 -s time.runtime=40000 & pid=$!; "
        "i=0; until [ -f run.h5 ] && py run.h5 swmr >/dev/null 2>&1; do "
        "i=$((i+1)); [ $i -lt 300 ] || { echo 'no run.h5'; exit 1; }; sleep 0.1; done; "
        "echo RUNNING; "
        "if h5ls run.h5 >/dev/null 2>&1; then echo 'h5ls read a running file'; fi; "
        "if HDF5_USE_FILE_LOCKING=FALSE h5ls run.h5 >/dev/null 2>&1; then "
        "echo 'h5ls read a running file without file locking'; fi; "
        "if h5dump -H run.h5 >/dev/null 2>&1; then echo 'h5dump read a running file'; fi; "
        "if py run.h5 plain >/dev/null 2>&1; then echo 'h5py read a running file without swmr'; "
        "fi; "
        "py run.h5 swmr || echo 'h5py swmr=True failed on a running file'; "
        "kill -9 $pid; { wait $pid; } 2>/dev/null; echo KILLED; "
        "if h5ls run.h5 >/dev/null 2>&1; then echo 'h5ls read a killed file'; fi; "
        "py run.h5 swmr || echo 'h5py swmr=True failed on a killed file'; "
        "cp run.h5 copy.h5 && h5clear -s copy.h5 && h5ls -r copy.h5 >/dev/null && "
        "echo 'h5ls read the copy after h5clear -s'; "
        "OMP_WAIT_POLICY=passive $B/cdem-run -q -o done.h5 -s assembly.height=2.5 "
        "-s time.equilibration=100 -s time.runtime=150 && h5ls done.h5 >/dev/null && "
        "echo 'h5ls read a completed file' 2>&1",
        d.dir, b && b[0] ? b : "build");
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    static char out[16384];
    size_t n = fread(out, 1, sizeof out - 1, p);
    out[n] = '\0';
    pclose(p);
    printf("%s", out);
    assert_non_null(strstr(out, "RUNNING\nrun.h5 h5py swmr "));
    assert_non_null(strstr(out, "KILLED\nrun.h5 h5py swmr "));
    assert_non_null(strstr(out, "h5ls read the copy after h5clear -s\n"));
    assert_non_null(strstr(out, "h5ls read a completed file\n"));
    /* what the page says the plain tools cannot do */
    assert_null(strstr(out, "h5ls read a running file"));
    assert_null(strstr(out, "h5dump read a running file"));
    assert_null(strstr(out, "h5py read a running file without swmr"));
    assert_null(strstr(out, "h5ls read a killed file"));
    assert_null(strstr(out, "failed"));
    assert_int_equal(scratch_dir_remove(&d), 0);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hdf5_tools_documented),
        cmocka_unit_test(test_hdf5_tools_running_killed_completed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
