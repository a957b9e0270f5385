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
    const char *tmp = getenv("CDEM_TEST_TMP");
    char dir[1024], run[1100], live[1100], ref[1100], cmd[4096];
    snprintf(dir, sizeof dir, "%s/follow_%d", tmp && *tmp ? tmp : "/tmp", (int)getpid());
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
              "time.runtime=220", "-s", "time.display_interval=4", "-o", run, (char *)NULL);
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
    }
    assert_int_equal(pclose(p), 0);
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    printf("follow: %d renders of %d different increments, last %d\n", renders, distinct, last);
    assert_true(distinct >= 2);
    assert_true(stopped);
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
        cmocka_unit_test(test_follow_usage_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
