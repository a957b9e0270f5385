/* make install / make uninstall (issue 18): the programs, man pages and bash completion go
 * under $(DESTDIR)$(PREFIX) and come back out, nothing else is touched. Runs make from the
 * repository root with BUILD=$CDEM_BUILD (already built: nothing is compiled) into a scratch
 * DESTDIR under $CDEM_TEST_TMP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static int sh(const char *cmd) {
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void test_install_and_uninstall(void **state) {
    (void)state;
    const char *b = getenv("CDEM_BUILD"), *t = getenv("CDEM_TEST_TMP");
    char dest[1024], cmd[4096], path[1200];
    snprintf(dest, sizeof dest, "%s/install_%d", t && t[0] ? t : "/tmp", (int)getpid());
    /* MAKEFLAGS of an enclosing make (its jobserver) must not leak into this one */
    snprintf(cmd, sizeof cmd,
             "env -u MAKEFLAGS -u MAKELEVEL make -s install BUILD='%s' DESTDIR='%s' "
             "PREFIX=/opt/cdem >/dev/null",
             b && b[0] ? b : "build", dest);
    assert_int_equal(sh(cmd), 0);
    const char *files[] = {"bin/cdem-run",
                           "bin/cdem-strain",
                           "share/man/man1/cdem-run.1",
                           "share/man/man1/cdem-strain.1",
                           "share/bash-completion/completions/cdem-run",
                           "share/bash-completion/completions/cdem-strain"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "%s/opt/cdem/%s", dest, files[i]);
        struct stat sb;
        if (stat(path, &sb) != 0)
            fail_msg("make install did not install %s", path);
        assert_int_equal(sb.st_mode & 0777, i < 2 ? 0755 : 0644);
    }
    /* the installed programs run, and the man page is the committed one */
    snprintf(cmd, sizeof cmd,
             "'%s/opt/cdem/bin/cdem-strain' -V >/dev/null && "
             "cmp -s man/cdem-strain.1 '%s/opt/cdem/share/man/man1/cdem-strain.1'",
             dest, dest);
    assert_int_equal(sh(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "env -u MAKEFLAGS -u MAKELEVEL make -s uninstall BUILD='%s' DESTDIR='%s' "
             "PREFIX=/opt/cdem >/dev/null && test -z \"$(find '%s' -type f)\"",
             b && b[0] ? b : "build", dest, dest);
    assert_int_equal(sh(cmd), 0);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dest);
    assert_int_equal(sh(cmd), 0);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_install_and_uninstall),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
