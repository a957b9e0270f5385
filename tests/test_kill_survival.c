/* Kill survival (docs/reliability.md, "Runs that survive"): runs $CDEM_BUILD/cdem-run on a
 * short model, kills it with SIGKILL at seeded random moments and checks that the reader
 * opens every file left behind, that the increments it lists are 0..k-1 and each loads
 * completely, that the series reads, and that `cdem-strain info` succeeds on it.
 * CDEM_KILLS (default 10) sets the number of kills, CDEM_KILL_SEED (default 20261122) the
 * seed of the moments; tests/validate/run_validate.sh runs 200. Scratch files go to
 * $CDEM_TEST_TMP. */
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
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static const char *build_dir(void) {
    const char *b = getenv("CDEM_BUILD");
    return b && *b ? b : "build";
}

static uint64_t rng_next(uint64_t *s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Starts cdem-run on the short model writing out; returns its pid. */
static pid_t start_run(const char *out) {
    char exe[1024];
    snprintf(exe, sizeof exe, "%s/cdem-run", build_dir());
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        execl(exe, exe, "-q", "-s", "assembly.height=2.5", "-s", "time.equilibration=150", "-s",
              "time.runtime=220", "-s", "time.display_interval=4", "-o", out, (char *)NULL);
        _exit(127);
    }
    return pid;
}

/* Opens path and loads everything; returns the increment count or fails the test. */
static size_t check_file(const char *path, char *stop, size_t stop_len) {
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("a killed run's file does not open: %s", err.msg);
    size_t n = cdem_h5_reader_increment_count(r);
    cdem_state s = {0};
    for (size_t i = 0; i < n; i++) {
        cdem_increment_info in;
        if (cdem_h5_reader_load_increment(r, i, &s, &in, &err) != CDEM_OK)
            fail_msg("%s: increment index %zu does not load: %s", path, i, err.msg);
        assert_int_equal(in.number, (int)i);
        assert_int_equal((long long)s.n, (long long)in.n_elements);
        assert_true(s.n > 1000); /* the short model has 1365 elements */
    }
    cdem_series_sample *smp = NULL;
    size_t ns = 0;
    if (cdem_h5_reader_read_series(r, &smp, &ns, &err) != CDEM_OK)
        fail_msg("%s: the series does not read: %s", path, err.msg);
    free(smp);
    snprintf(stop, stop_len, "%s", cdem_h5_reader_stop_reason(r));
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
    char cmd[4800], log[1100];
    snprintf(log, sizeof log, "%s.info", path);
    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' info '%s' >'%s' 2>&1", build_dir(), path, log);
    if (system(cmd) != 0) {
        char text[2048] = "";
        FILE *f = fopen(log, "r");
        if (f) {
            size_t got = fread(text, 1, sizeof text - 1, f);
            text[got] = '\0';
            fclose(f);
        }
        snprintf(cmd, sizeof cmd, "cp '%s' '%s.failed.h5'", path, path);
        if (system(cmd) != 0)
            text[0] = text[0];
        fail_msg("cdem-strain info fails on %s (kept as %s.failed.h5): %s", path, path, text);
    }
    remove(log);
    return n;
}

static void test_kill_survival_random_moments(void **state) {
    (void)state;
    char out[1024];
    scratch_path(out, sizeof out, "kill.h5");
    const char *ek = getenv("CDEM_KILLS"), *es = getenv("CDEM_KILL_SEED");
    int kills = ek && *ek ? atoi(ek) : 10;
    uint64_t seed = es && *es ? strtoull(es, NULL, 10) : 20261122u;

    /* One complete run gives the duration the kill moments are spread over. */
    double t0 = now_s();
    pid_t pid = start_run(out);
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    double duration = now_s() - t0;
    char stop[64];
    size_t full = check_file(out, stop, sizeof stop);
    assert_string_equal(stop, "completed");

    int no_file = 0, finished = 0, opened = 0;
    size_t min_inc = (size_t)-1, max_inc = 0;
    double min_t = 1e9, max_t = 0.0;
    for (int k = 0; k < kills; k++) {
        remove(out);
        double delay = duration * 1.05 * (double)(rng_next(&seed) >> 11) * 0x1.0p-53;
        pid = start_run(out);
        struct timespec ts = {(time_t)delay, (long)((delay - (double)(time_t)delay) * 1e9)};
        nanosleep(&ts, NULL);
        kill(pid, SIGKILL);
        assert_true(waitpid(pid, &status, 0) == pid);
        if (access(out, F_OK) != 0) {
            no_file++; /* killed before the file was created (it appears complete or not) */
            continue;
        }
        size_t n = check_file(out, stop, sizeof stop);
        opened++;
        if (WIFEXITED(status))
            finished++;
        else
            assert_true(strcmp(stop, "running") == 0 || strcmp(stop, "completed") == 0);
        min_inc = n < min_inc ? n : min_inc;
        max_inc = n > max_inc ? n : max_inc;
        min_t = delay < min_t ? delay : min_t;
        max_t = delay > max_t ? delay : max_t;
        assert_true(n <= full);
    }
    printf("kill survival: %d kills at %.2f..%.2f s of a %.2f s run (%zu increments): %d files "
           "opened with %zu..%zu complete increments, %d before the file existed, %d runs had "
           "finished, 0 failures\n",
           kills, min_t, max_t, duration, full, opened, opened ? min_inc : 0, max_inc, no_file,
           finished);
    remove(out);
    char xmf[1100];
    snprintf(xmf, sizeof xmf, "%.*s.xmf", (int)(strlen(out) - 3), out);
    remove(xmf);
}

/* A full disk during the run (RLIMIT_FSIZE in the child, as `ulimit -f` sets it): cdem-run
 * stops with exit status 1 and a message naming the file, and the file keeps every increment
 * written before, with stop reason "write-failure". The child leaves SIGXFSZ at its default
 * (kill the process): cdem-run itself must ignore it so that the write fails with EFBIG
 * instead (once it died silently; only this test, ignoring the signal, made it work). */
static void test_kill_survival_file_size_limit(void **state) {
    (void)state;
    char out[1024], errf[1100];
    scratch_path(out, sizeof out, "limit.h5");
    snprintf(errf, sizeof errf, "%s.err", out);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        signal(SIGXFSZ, SIG_DFL);
        struct rlimit rl = {400 * 1024, 400 * 1024};
        if (setrlimit(RLIMIT_FSIZE, &rl) != 0 || !freopen(errf, "w", stderr))
            _exit(126);
        char exe[1024];
        snprintf(exe, sizeof exe, "%s/cdem-run", build_dir());
        execl(exe, exe, "-q", "-s", "assembly.height=2.5", "-s", "time.equilibration=150", "-s",
              "time.runtime=220", "-s", "time.display_interval=4", "-o", out, (char *)NULL);
        _exit(127);
    }
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 1);
    FILE *f = fopen(errf, "r");
    assert_non_null(f);
    char msg[4096] = "";
    size_t got = fread(msg, 1, sizeof msg - 1, f);
    msg[got] = '\0';
    fclose(f);
    assert_non_null(strstr(msg, out));
    assert_non_null(strstr(msg, "disk full?"));
    assert_non_null(strstr(msg, "File too large")); /* EFBIG, said plainly (issue 19, item 7) */
    assert_null(strstr(msg, "18446744073709551615"));
    assert_null(strstr(msg, ".creating"));
    char stop[64];
    size_t n = check_file(out, stop, sizeof stop);
    assert_string_equal(stop, "write-failure");
    printf("file size limit: cdem-run stopped after %zu increments: %.120s...\n", n, msg);
    assert_true(n >= 1);
    remove(out);
    remove(errf);
    char xmf[1100];
    snprintf(xmf, sizeof xmf, "%.*s.xmf", (int)(strlen(out) - 3), out);
    remove(xmf);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kill_survival_random_moments),
        cmocka_unit_test(test_kill_survival_file_size_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
