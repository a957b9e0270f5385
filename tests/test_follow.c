/* Live monitoring: `cdem-strain render RUN --follow` on a run that $CDEM_BUILD/cdem-run is
 * still writing re-renders the newest increment as increments arrive, exits when the run
 * stops, and leaves the picture of the last increment; `cdem-strain info` works on the
 * running file. Scratch files go to $CDEM_TEST_TMP. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "h5format.h"
#include "scratch.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static const char *build_dir(void) {
    const char *b = getenv("CDEM_BUILD");
    return b && *b ? b : "build";
}

static void test_follow_renders_new_increments(void **state) {
    (void)state;
    char dir[1024], run[1100], live[1100], ref[1100], cmd[4096];
    scratch_path(dir, sizeof dir, "follow");
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    assert_int_equal(system(cmd), 0);
    snprintf(run, sizeof run, "%s/run.h5", dir);
    snprintf(live, sizeof live, "%s/live.png", dir);
    snprintf(ref, sizeof ref, "%s/ref.png", dir);
    char exe[1100];
    snprintf(exe, sizeof exe, "%s/cdem-run", build_dir());
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        execl(exe, exe, "-q", "-s", "assembly.height=2.5", "-s", "time.equilibration=150", "-s",
              "time.runtime=220", "-s", "time.display_interval=0.85", "-o", run, (char *)NULL);
        _exit(127);
    }
    /* info on the running file, as soon as it exists */
    for (int i = 0; i < 200 && access(run, F_OK) != 0; i++) {
        struct timespec ts = {0, 20000000};
        nanosleep(&ts, NULL);
    }
    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' info '%s' > '%s/info.txt' 2>&1", build_dir(), run,
             dir);
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' render '%s' --follow -o '%s' --interval 0.1 2>&1",
             build_dir(), run, live);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    char line[2048];
    int renders = 0, distinct = 0, last = -1, stopped = 0;
    while (fgets(line, sizeof line, p)) {
        const char *at = strstr(line, ": increment ");
        if (at) {
            int k = atoi(at + 12);
            renders++;
            distinct += k != last;
            assert_true(k > last); /* only newer increments */
            last = k;
        }
        if (strstr(line, "the run stopped (completed)"))
            stopped = 1;
        if (strstr(line, "follow it again")) /* a completed run is not continued */
            fail_msg("follow offered to follow a completed run again: %s", line);
        if (!at && !strstr(line, "the run stopped"))
            printf("follow said: %s", line); /* an error, shown when the test fails */
    }
    assert_int_equal(pclose(p), 0);
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    printf("follow: %d renders of %d different increments, last %d\n", renders, distinct, last);
    assert_true(distinct >= 2);
    assert_true(stopped);
    /* 184 increments: the follower went past the chunks of /increments/index (48 rows; 64
     * in files written before), where it once read a row the writer had not yet written
     * (issue 35, item 2: "increment numbers must be >= 0 and increasing" at row 64) */
    assert_true(last >= 3 * 48);
    /* The final picture is the last increment. */
    cdem_error err;
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(run, &r, &err), CDEM_OK);
    cdem_increment_info in;
    size_t n = cdem_h5_reader_increment_count(r);
    assert_int_equal(cdem_h5_reader_increment_info(r, n - 1, &in, &err), CDEM_OK);
    assert_int_equal(in.number, last);
    cdem_h5_reader_close(r);
    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' render '%s' --increment last -o '%s' >/dev/null",
             build_dir(), run, ref);
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "cmp -s '%s' '%s'", live, ref);
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

/* Usage errors of --follow. */
/* A killed run's file (stop reason "running", nobody holding its lock): --follow renders the
 * last increment and ends with a message instead of waiting for ever (issue 19, item 1: a
 * reader must not wait for a writer that is gone). */
static void test_follow_ends_when_the_writer_is_gone(void **state) {
    (void)state;
    const char *data = getenv("CDEM_TEST_DATA");
    char dir[1024], run[1100], live[1100], cmd[4200];
    scratch_path(dir, sizeof dir, "follow_dead");
    snprintf(run, sizeof run, "%s/killed.h5", dir);
    snprintf(live, sizeof live, "%s/live.png", dir);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s' && cp '%s/damaged/killed.h5' '%s'", dir,
             data && *data ? data : "tests/data", run);
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "timeout 60 '%s/cdem-strain' render '%s' --follow -o '%s' --interval 0.1 "
             "> '%s/out.txt' 2>&1",
             build_dir(), run, live, dir);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int st = system(cmd);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    assert_true(WIFEXITED(st));
    if (WEXITSTATUS(st) == 124)
        fail_msg("render --follow still waited for a dead writer after %.0f s", secs);
    assert_int_equal(WEXITSTATUS(st), 1);
    char out[4096] = "";
    snprintf(cmd, sizeof cmd, "%s/out.txt", dir);
    FILE *f = fopen(cmd, "r");
    assert_non_null(f);
    size_t got = fread(out, 1, sizeof out - 1, f);
    out[got] = '\0';
    fclose(f);
    assert_non_null(strstr(out, "its writer is gone"));
    assert_non_null(strstr(out, "cdem-run --resume"));
    /* and how to follow the resumed run: --follow does not wait for it (issue 46, 13e) */
    char again[3400];
    snprintf(again, sizeof again,
             "then follow it again with cdem-strain render %s --follow -o %s (and the same "
             "options): --follow does not wait for a resume",
             run, live);
    if (!strstr(out, again))
        fail_msg("missing \"%s\" in:\n%s", again, out);
    assert_int_equal(access(live, F_OK), 0); /* its last increment was rendered */
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

/* A run that stopped and can be continued (--max-steps: "stopped-early"): --follow renders
 * its last increment, exits 0 and says how to follow the run once it is resumed (issue 46,
 * item 13e: it ended without a word of it, and a resume started after it had gone was not
 * followed). */
static void test_follow_says_how_to_follow_a_resumed_run(void **state) {
    (void)state;
    char dir[1024], run[1100], live[1100], cmd[4400], out[4096] = "";
    scratch_path(dir, sizeof dir, "follow_stopped");
    snprintf(run, sizeof run, "%s/stopped.h5", dir);
    snprintf(live, sizeof live, "%s/live.png", dir);
    snprintf(cmd, sizeof cmd,
             "mkdir -p '%s' && '%s/cdem-run' -q -s assembly.height=2.5 -s "
             "time.equilibration=150 -s time.display_interval=0.85 --max-steps 200 -o '%s' "
             ">/dev/null 2>&1",
             dir, build_dir(), run);
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "timeout 60 '%s/cdem-strain' render '%s' --follow -o '%s' --interval 0.1 "
             "> '%s/out.txt' 2>&1",
             build_dir(), run, live, dir);
    const int st = system(cmd);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    snprintf(cmd, sizeof cmd, "%s/out.txt", dir);
    FILE *f = fopen(cmd, "r");
    assert_non_null(f);
    out[fread(out, 1, sizeof out - 1, f)] = '\0';
    fclose(f);
    char want[5000];
    snprintf(want, sizeof want, "%s: the run stopped (stopped-early), last increment ", run);
    if (!strstr(out, want))
        fail_msg("missing \"%s\" in:\n%s", want, out);
    snprintf(want, sizeof want,
             "%s: after cdem-run --resume %s, follow it again with cdem-strain render %s "
             "--follow -o %s (and the same options): --follow does not wait for a resume",
             run, run, run, live);
    if (!strstr(out, want))
        fail_msg("missing \"%s\" in:\n%s", want, out);
    assert_int_equal(access(live, F_OK), 0);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static void test_follow_usage_errors(void **state) {
    (void)state;
    char cmd[2048];
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-strain' render x.h5 --follow --gif a.gif 2>&1 | grep -q 'cannot be "
             "combined'",
             build_dir());
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "'%s/cdem-strain' render x.h5 --follow --interval 0 2>&1 | grep -q 'expected "
             "seconds > 0'",
             build_dir());
    assert_int_equal(system(cmd), 0);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_follow_renders_new_increments),
        cmocka_unit_test(test_follow_ends_when_the_writer_is_gone),
        cmocka_unit_test(test_follow_says_how_to_follow_a_resumed_run),
        cmocka_unit_test(test_follow_usage_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
