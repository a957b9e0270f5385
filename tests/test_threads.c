/* Tests of threads.[ch]: the --threads value parser, and the wait-policy re-execution (a
 * child process calls cdem_threads_settle_wait_policy; when it re-executes this test binary
 * with --report-spin, the new process prints the OMP_WAIT_POLICY it started with). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "threads.h"

static char *self_path;

static void test_threads_parse(void **st) {
    (void)st;
    int n = 0;
    assert_int_equal(cdem_threads_parse("1", &n), 0);
    assert_int_equal(n, 1);
    assert_int_equal(cdem_threads_parse("1024", &n), 0);
    assert_int_equal(n, 1024);
    static const char *const bad[] = {"0",  "-2", "+2",  "1025",
                                      "2x", "",   "two", "99999999999999999999"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        n = 7;
        assert_int_equal(cdem_threads_parse(bad[k], &n), -1);
        assert_int_equal(n, 7); /* untouched */
    }
}

/* Runs a child with the environment changes in `set` ("NAME=value") and `unset` applied; the
 * child calls the settle function with argv {self, "--report-spin"}; returns what it printed. */
static void child_report(const char *const *set, const char *const *unset, char *out, size_t cap) {
    int fd[2];
    assert_int_equal(pipe(fd), 0);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        dup2(fd[1], STDOUT_FILENO);
        close(fd[0]);
        for (size_t k = 0; unset && unset[k]; k++)
            unsetenv(unset[k]);
        for (size_t k = 0; set && set[k]; k++)
            putenv((char *)set[k]);
        char *argv[] = {self_path, "--report-spin", NULL};
        cdem_threads_settle_wait_policy(argv);
        printf("not re-executed\n"); /* returned: nothing to do */
        fflush(stdout);
        _exit(0);
    }
    close(fd[1]);
    size_t len = 0;
    ssize_t r;
    while (len + 1 < cap && (r = read(fd[0], out + len, cap - 1 - len)) > 0)
        len += (size_t)r;
    out[len] = '\0';
    close(fd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

static void test_threads_wait_policy(void **st) {
    (void)st;
    static const char *const all[] = {"OMP_WAIT_POLICY", "GOMP_SPINCOUNT", "CDEM_NO_REEXEC", NULL};
    char out[256];
    /* nothing set: re-executed with the passive wait policy */
    child_report(NULL, all, out, sizeof out);
    assert_string_equal(out, "OMP_WAIT_POLICY=" CDEM_WAIT_POLICY "\n");
    /* the user's choices are honoured: no re-execution */
    static const char *const passive[] = {"OMP_WAIT_POLICY=passive", NULL};
    child_report(passive, all, out, sizeof out);
    assert_string_equal(out, "not re-executed\n");
    static const char *const spin[] = {"GOMP_SPINCOUNT=5", NULL};
    child_report(spin, all, out, sizeof out);
    assert_string_equal(out, "not re-executed\n");
    static const char *const off[] = {"CDEM_NO_REEXEC=1", NULL};
    child_report(off, all, out, sizeof out);
    assert_string_equal(out, "not re-executed\n");
}

int main(int argc, char **argv) {
    if (argc > 1 && !strcmp(argv[1], "--report-spin")) {
        const char *v = getenv("OMP_WAIT_POLICY");
        printf("OMP_WAIT_POLICY=%s\n", v ? v : "(unset)");
        return 0;
    }
    self_path = argv[0];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_threads_parse),
        cmocka_unit_test(test_threads_wait_policy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
