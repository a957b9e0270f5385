/* test_equil_end: what cdem-strain says about a run that is not finished (issue 35, item 9).
 * A killed run's `info` said "stop reason: running", as for a live run; and for runs stopped
 * or killed during equilibration it said "end of equilibration: increment 42" (the last
 * increment written) when the real end was 56, and `--increment equil` and the total and
 * cumulative quantities silently used that increment as the end. Now a killed run is
 * "interrupted (no writer holds it)" with what to do, and the end of equilibration is known
 * only once an increment of a later phase follows it (or the run completed): until then
 * `info` says it is not reached, `--increment equil` fails and the quantities measured from
 * it say they are not defined yet. Runs cdem-run and cdem-strain from $CDEM_BUILD; files go
 * to a scratch folder. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "analysis.h"
#include "run_file.h"
#include "h5format.h"
#include "runlock.h"
#include "scratch.h"

#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static scratch_dir g_dir;
static char g_strain[1100], g_run[1100];

static int setup(void **state) {
    (void)state;
    if (scratch_dir_make(&g_dir, "equil_end") != 0)
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

/* The increments of path (0 while it cannot be opened). */
static size_t increments_of(const char *path) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        return 0;
    const size_t n = cdem_h5_reader_increment_count(r);
    cdem_h5_reader_close(r);
    return n;
}

/* The short model with an equilibration of 400 s (14 200 steps, a second or two), killed with
 * SIGKILL once it has written `at` increments: a run killed during equilibration, with a
 * checkpoint after every increment. */
static void killed_in_equilibration(const char *name, size_t at) {
    char path[1200];
    scratch_dir_path(&g_dir, path, sizeof path, name);
    fflush(NULL);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        const int null = open("/dev/null", O_WRONLY);
        dup2(null, 1);
        dup2(null, 2);
        setenv("OMP_NUM_THREADS", "1", 1);
        setenv("OMP_WAIT_POLICY", "passive", 1);
        execl(g_run, g_run, "-q", "-o", path, "-s", "assembly.width=10", "-s",
              "assembly.height=2.5", "-s", "time.equilibration=400", "-s", "time.runtime=450", "-s",
              "output.checkpoint_interval=1", (char *)NULL);
        _exit(127);
    }
    const struct timespec tick = {0, 20 * 1000 * 1000};
    for (int i = 0; i < 6000 && increments_of(path) < at; i++)
        nanosleep(&tick, NULL);
    kill(pid, SIGKILL);
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_true(WIFSIGNALED(status));
    /* the kill must have come during equilibration (about 1000 of 14 200 steps) */
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    const size_t n = cdem_h5_reader_increment_count(r);
    cdem_increment_info last;
    assert_true(n >= at);
    assert_int_equal(cdem_h5_reader_increment_info(r, n - 1, &last, &err), CDEM_OK);
    assert_int_equal(last.phase, CDEM_PHASE_EQUILIBRATION);
    assert_int_equal(cdem_h5_reader_writer_alive(r), 0);
    size_t idx = 0;
    assert_int_equal(cdem_h5_reader_equil_end(r, &idx, &err), CDEM_ERR_NOTFOUND);
    HAS(err.msg, "the end of equilibration is not reached: the run stopped during equilibration");
    assert_int_equal(cdem_h5_reader_find_increment(r, "equil", &idx, &err), CDEM_ERR_NOTFOUND);
    cdem_h5_reader_close(r);
}

/* info, --json, --increment equil, the total and cumulative quantities of a killed run. */
static void test_equil_end_killed_run(void **state) {
    (void)state;
    killed_in_equilibration("killed.h5", 4);
    char out[1 << 16];
    assert_int_equal(run(out, sizeof out, "%s info killed.h5", g_strain), 0);
    HAS(out, "stop reason: interrupted (no writer holds it): continue with cdem-run --resume "
             "killed.h5\n");
    HAS(out, "(end of equilibration: not reached: the run stopped during equilibration)\n");
    assert_null(strstr(out, "stop reason: running"));
    assert_int_equal(run(out, sizeof out, "%s info killed.h5 --json", g_strain), 0);
    HAS(out, "\"writer_alive\": false,");
    HAS(out, "\"stop_reason\": \"interrupted\",");
    HAS(out, "\"stop_detail\": \"no writer holds it: continue with cdem-run --resume killed.h5\"");
    HAS(out, "\"recorded_stop_reason\": \"running\",");
    HAS(out, "\"end_of_equilibration\": null,");
    HAS(out, "\"end_of_equilibration_note\": \"the end of equilibration is not reached");
    /* --increment equil fails, naming why */
    assert_int_equal(run(out, sizeof out,
                         "%s compute killed.h5 --increment equil --quantity incr-disp-mag",
                         g_strain),
                     1);
    HAS(out, "killed.h5: increment 'equil': the end of equilibration is not reached: the run "
             "stopped during equilibration (its last increment, ");
    /* totals and cumulative quantities are not defined; incremental ones are */
    const char *from_equil[] = {"total-disp-mag", "total-e1", "cum-max-shear"};
    for (size_t k = 0; k < 3; k++) {
        assert_int_equal(run(out, sizeof out, "%s compute killed.h5 --increment last --quantity %s",
                             g_strain, from_equil[k]),
                         1);
        HAS(out, from_equil[k]);
        HAS(out, "is not defined yet: it is measured from the end of equilibration, which is not "
                 "reached: the run stopped during equilibration");
    }
    assert_int_equal(run(out, sizeof out,
                         "%s compute killed.h5 --increment last --quantity incr-disp-mag",
                         g_strain),
                     0);
    assert_int_equal(
        run(out, sizeof out, "%s limits killed.h5 --increment last --quantity total-e1", g_strain),
        1);
    HAS(out, "total-e1 is not defined yet");
    assert_int_equal(run(out, sizeof out,
                         "%s render killed.h5 --color total-max-shear -o t.png --width 200",
                         g_strain),
                     1);
    HAS(out, "is not defined yet");
    assert_int_equal(
        run(out, sizeof out, "%s render killed.h5 --vectors total -o v.png --width 200", g_strain),
        1);
    HAS(out, "is not defined yet");
    assert_int_equal(run(out, sizeof out, "%s faults killed.h5", g_strain), 1); /* total-... */
    HAS(out, "is not defined yet");
    assert_int_equal(
        run(out, sizeof out, "%s element killed.h5 --increment last --element 7", g_strain), 0);
    HAS(out, "  total-disp-mag     not defined yet (measured from the end of equilibration, not "
             "reached)\n");
    HAS(out, "  cum-e1             not defined yet");
    HAS(out, "  incr-disp-mag      ");
    /* resumed to the end: the end of equilibration is known, after the increment the killed
     * run stopped at */
    assert_int_equal(run(out, sizeof out,
                         "OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive %s -q --resume killed.h5",
                         g_run),
                     0);
    assert_int_equal(run(out, sizeof out, "%s info killed.h5", g_strain), 0);
    HAS(out, "stop reason: completed");
    HAS(out, "(end of equilibration: increment 56)");
}

/* The same file while a writer holds its lock (as a live run's): "running", and still in
 * equilibration; render --follow of a total quantity waits for the end of equilibration
 * instead of failing, and fails (saying why) once the writer is gone without reaching it. */
static void test_equil_end_live_run(void **state) {
    (void)state;
    killed_in_equilibration("live.h5", 3);
    char path[1200], out[1 << 16];
    scratch_dir_path(&g_dir, path, sizeof path, "live.h5");
    cdem_runlock *lock = NULL;
    cdem_error err;
    assert_int_equal(cdem_runlock_acquire(path, "test_equil_end", &lock, &err), CDEM_OK);
    assert_int_equal(run(out, sizeof out, "%s info live.h5", g_strain), 0);
    HAS(out, "stop reason: running\n");
    HAS(out, "(end of equilibration: not reached: the run is still in equilibration)\n");
    assert_int_equal(run(out, sizeof out, "%s info live.h5 --json", g_strain), 0);
    HAS(out, "\"writer_alive\": true,");
    HAS(out, "\"stop_reason\": \"running\",");
    /* follow a total quantity: a note, no failure, until the writer is gone */
    char cmd[4400];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && %s render live.h5 --follow --interval 0.1 --color total-disp-mag -o "
             "f.png --width 200 > follow.log 2>&1",
             g_dir.dir, g_strain);
    fflush(NULL);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        execl("/bin/sh", "sh", "-c", cmd, (char *)NULL);
        _exit(127);
    }
    const struct timespec wait = {1, 500 * 1000 * 1000};
    nanosleep(&wait, NULL);
    int status = 0;
    assert_int_equal(waitpid(pid, &status, WNOHANG), 0); /* still following */
    cdem_runlock_release(lock);
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 1);
    assert_int_equal(run(out, sizeof out, "cat follow.log"), 0);
    HAS(out, "note: live.h5: total-disp-mag is measured from the end of equilibration, which the "
             "run has not reached yet: waiting for it\n");
    /* (the colour limits, taken first since the render draws its own increment, say it) */
    HAS(out, "live.h5: total-disp-mag is not defined yet: it is measured from the end of "
             "equilibration, which is not reached");
    assert_int_equal(run(out, sizeof out, "test -e f.png || echo none"), 0);
    HAS(out, "none");
}

/* A run killed before its first checkpoint cannot be resumed: info says so instead. Made by a
 * writer in a child that exits without closing, as a killed writer leaves its file. */
static void test_equil_end_killed_before_checkpoint(void **state) {
    (void)state;
    char path[1200], out[1 << 16];
    scratch_dir_path(&g_dir, path, sizeof path, "early.h5");
    fflush(NULL);
    const pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        cdem_params p;
        cdem_params_defaults(&p);
        cdem_run_meta meta = {&p, "", "summary", "0", "cdem-run", 0};
        cdem_h5_writer *w = NULL;
        cdem_error err;
        if (cdem_h5_writer_create(path, &meta, &w, &err) != CDEM_OK)
            _exit(2);
        cdem_state s = {0};
        cdem_state_init(&s, 4, 0, &err);
        for (int i = 0; i < 4; i++)
            cdem_state_append(&s, -1, 100.0 * i, 50.0, 50.0, 1.0, 1, 0, 0, NULL, &err);
        for (int k = 0; k < 2; k++) {
            cdem_increment_info in = {.number = k, .step = 10 * k, .time = k, .sea_level = NAN};
            if (cdem_h5_writer_write_increment(w, &in, &s, &err) != CDEM_OK)
                _exit(3);
        }
        _exit(0); /* without closing: a killed writer's file */
    }
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    assert_int_equal(run(out, sizeof out, "%s info early.h5", g_strain), 0);
    HAS(out, "stop reason: interrupted (no writer holds it): it cannot be resumed: its writer was "
             "killed before the first checkpoint; run it again\n");
    HAS(out, "(end of equilibration: not reached: the run stopped during equilibration)");
}

/* A run stopped by --max-steps during equilibration: its last increment (6) is not the end
 * (14); resumed, the end is known. */
static void test_equil_end_stopped_early(void **state) {
    (void)state;
    char out[1 << 16];
    assert_int_equal(
        run(out, sizeof out,
            "OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive %s -q -o stopped.h5 --max-steps "
            "1600 -s assembly.width=10 -s assembly.height=2.5 -s "
            "time.equilibration=100 -s time.runtime=150",
            g_run),
        0);
    assert_int_equal(run(out, sizeof out, "%s info stopped.h5", g_strain), 0);
    HAS(out, "stop reason: stopped-early: max_steps = 1600 reached at step 1600");
    HAS(out, "(end of equilibration: not reached: the run stopped during equilibration)\n");
    assert_int_equal(run(out, sizeof out,
                         "%s compute stopped.h5 --increment equil --quantity incr-e1", g_strain),
                     1);
    HAS(out, "stopped.h5: increment 'equil': the end of equilibration is not reached");
    assert_int_equal(run(out, sizeof out,
                         "OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive %s -q --resume stopped.h5",
                         g_run),
                     0);
    assert_int_equal(run(out, sizeof out, "%s info stopped.h5", g_strain), 0);
    HAS(out, "(end of equilibration: increment 14)\n");
    assert_int_equal(run(out, sizeof out,
                         "%s compute stopped.h5 --increment equil --quantity total-e1", g_strain),
                     0);
}

/* The rule in the library: states in memory that end in equilibration have no end of
 * equilibration; one deformation increment gives it; a completed file whose increments are
 * all of equilibration has it (the run ended there). */
static void test_equil_end_rule(void **state) {
    (void)state;
    enum { N = 4 };
    cdem_state st[N];
    cdem_increment_info in[N];
    cdem_error err;
    for (int k = 0; k < N; k++) {
        memset(&st[k], 0, sizeof st[k]);
        cdem_state_init(&st[k], 3, 0, &err);
        for (int i = 0; i < 3; i++)
            cdem_state_append(&st[k], i, 100.0 * i + k, 50.0, 50.0, 1.0, 1, 0, 0, NULL, &err);
        in[k] = (cdem_increment_info){.number = k, .step = k, .time = k, .sea_level = NAN};
    }
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_analysis *a = NULL;
    assert_int_equal(cdem_analysis_open_states(st, in, N, &p, &a, &err), CDEM_OK);
    assert_int_equal(cdem_analysis_equil_known(a), 0);
    size_t idx = 0;
    assert_int_equal(cdem_analysis_find(a, "equil", &idx, &err), CDEM_ERR_NOTFOUND);
    const cdem_quantity *q = NULL;
    assert_int_equal(cdem_quantity_find("total-disp-x", &q, &err), CDEM_OK);
    const cdem_state *s = NULL;
    double *v = NULL;
    assert_int_equal(cdem_analysis_values(a, N - 1, q, &s, &v, &err), CDEM_ERR_NOTFOUND);
    HAS(err.msg, "total-disp-x at increment 3 is not defined yet");
    cdem_axes ax;
    assert_int_equal(cdem_analysis_axes(a, N - 1, CDEM_AXES_TOTAL_STRAIN, &ax, &err),
                     CDEM_ERR_NOTFOUND);
    cdem_analysis_close(a);
    in[N - 1].phase = CDEM_PHASE_DEFORMATION;
    assert_int_equal(cdem_analysis_open_states(st, in, N, &p, &a, &err), CDEM_OK);
    assert_int_equal(cdem_analysis_equil_known(a), 1);
    assert_int_equal(cdem_analysis_find(a, "equil", &idx, &err), CDEM_OK);
    assert_int_equal(idx, N - 2);
    assert_int_equal(cdem_analysis_values(a, N - 1, q, &s, &v, &err), CDEM_OK);
    assert_true(v[1] == 1.0); /* x moved by 1 m from the end of equilibration */
    free(v);
    cdem_analysis_close(a);
    /* a completed file of equilibration increments only */
    char path[1200];
    scratch_dir_path(&g_dir, path, sizeof path, "all_equil.h5");
    cdem_run_meta meta = {&p, "", "", "0", "cdem-run", 0};
    cdem_h5_writer *w = NULL;
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    in[N - 1].phase = CDEM_PHASE_EQUILIBRATION;
    for (int k = 0; k < N; k++)
        assert_int_equal(cdem_h5_writer_write_increment(w, &in[k], &st[k], &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_set_stop_reason(w, "completed", "", &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_equil_end(r, &idx, &err), CDEM_OK);
    assert_int_equal(idx, N - 1);
    cdem_h5_reader_close(r);
    assert_int_equal(cdem_analysis_open(path, &a, &err), CDEM_OK);
    assert_int_equal(cdem_analysis_equil_known(a), 1);
    cdem_analysis_close(a);
    for (int k = 0; k < N; k++)
        cdem_state_free(&st[k]);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_equil_end_killed_run),
        cmocka_unit_test(test_equil_end_live_run),
        cmocka_unit_test(test_equil_end_killed_before_checkpoint),
        cmocka_unit_test(test_equil_end_stopped_early),
        cmocka_unit_test(test_equil_end_rule),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
