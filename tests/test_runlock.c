/* runlock (common/runlock.h): one writer per run file. A second lock of the same path fails
 * at once naming the holder (pid, start time); the lock dies with its holder; the lock file
 * goes away with a normal release; a missing folder is named as such. Scratch files go to
 * $CDEM_TEST_TMP. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "runlock.h"
#include "scratch.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

static void test_runlock_second_writer_refused(void **state) {
    (void)state;
    char path[1024], lock[1100], pid[64];
    scratch_path(path, sizeof path, "locked.h5");
    assert_int_equal(cdem_runlock_path(path, lock, sizeof lock), 0);
    cdem_error err;
    cdem_runlock *a = NULL, *b = NULL;
    assert_int_equal(cdem_runlock_acquire(path, "cdem-run", &a, &err), CDEM_OK);
    assert_int_equal(cdem_runlock_effective(a), 1);
    assert_int_equal(access(lock, F_OK), 0);
    /* another handle, even of this process, is refused at once, naming the holder */
    assert_int_equal(cdem_runlock_acquire(path, "cdem-run", &b, &err), CDEM_ERR_CONFLICT);
    assert_null(b);
    snprintf(pid, sizeof pid, "cdem-run pid %d, started ", (int)getpid());
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, pid));
    assert_non_null(strstr(err.msg, "being written by another process"));
    char holder[512];
    assert_int_equal(cdem_runlock_probe(path, holder, sizeof holder), 1);
    assert_non_null(strstr(holder, pid));
    assert_int_equal(cdem_runlock_check(path, &err), CDEM_ERR_CONFLICT);
    cdem_runlock_release(a);
    /* released: the lock file is gone and the path is free */
    assert_int_not_equal(access(lock, F_OK), 0);
    assert_int_equal(cdem_runlock_probe(path, NULL, 0), 0);
    assert_int_equal(cdem_runlock_check(path, &err), CDEM_OK);
    assert_int_equal(cdem_runlock_acquire(path, "cdem-run", &b, &err), CDEM_OK);
    cdem_runlock_release(b);
    cdem_runlock_release(NULL);
}

/* A holder killed with SIGKILL leaves its lock file but no lock: the next writer takes it. */
static void test_runlock_dies_with_its_holder(void **state) {
    (void)state;
    char path[1024], lock[1100];
    scratch_path(path, sizeof path, "killed.h5");
    cdem_runlock_path(path, lock, sizeof lock);
    int ready[2];
    assert_int_equal(pipe(ready), 0);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        cdem_error e;
        cdem_runlock *l = NULL;
        char c = cdem_runlock_acquire(path, "child", &l, &e) == CDEM_OK ? 'y' : 'n';
        if (write(ready[1], &c, 1) != 1)
            _exit(1);
        for (;;)
            pause();
    }
    char c = 0;
    assert_int_equal(read(ready[0], &c, 1), 1);
    assert_int_equal(c, 'y');
    cdem_error err;
    cdem_runlock *l = NULL;
    char who[64];
    snprintf(who, sizeof who, "child pid %d", (int)pid);
    assert_int_equal(cdem_runlock_acquire(path, "parent", &l, &err), CDEM_ERR_CONFLICT);
    assert_non_null(strstr(err.msg, who));
    kill(pid, SIGKILL);
    int status = 0;
    assert_true(waitpid(pid, &status, 0) == pid);
    assert_int_equal(access(lock, F_OK), 0);                /* the stale lock file stays ... */
    assert_int_equal(cdem_runlock_probe(path, NULL, 0), 0); /* ... but nobody holds it */
    assert_int_equal(cdem_runlock_acquire(path, "parent", &l, &err), CDEM_OK);
    char holder[512];
    assert_int_equal(cdem_runlock_probe(path, holder, sizeof holder), 1);
    assert_non_null(strstr(holder, "parent pid")); /* the stale line was replaced */
    cdem_runlock_release(l);
    close(ready[0]);
    close(ready[1]);
}

static void test_runlock_missing_folder(void **state) {
    (void)state;
    cdem_error err;
    cdem_runlock *l = NULL;
    assert_int_equal(cdem_runlock_acquire("/nonexistent-dir/x/run.h5", "cdem-run", &l, &err),
                     CDEM_ERR_IO);
    assert_null(l);
    assert_non_null(strstr(err.msg, "cannot write /nonexistent-dir/x/run.h5: folder "
                                    "/nonexistent-dir/x does not exist"));
    assert_int_equal(cdem_runlock_probe("/nonexistent-dir/x/run.h5", NULL, 0), 0);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runlock_second_writer_refused),
        cmocka_unit_test(test_runlock_dies_with_its_holder),
        cmocka_unit_test(test_runlock_missing_folder),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
