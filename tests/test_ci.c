/* The CI entry point runs the README's test command, exactly (issue 18): a user who types
 * the README's second command gets what CI checked. Before, .ci/run ran `make -j2 test` and
 * `make -j2 asan` while the README said `make deps && make test && make asan`, and a crash
 * that depended on the build was missed. Runs from the repository root. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The first line of path that starts with prefix, without its comment (after " #") and
 * trailing blanks, into out; 0 when there is none. */
static int first_line(const char *path, const char *prefix, char *out, size_t cap) {
    FILE *f = fopen(path, "r");
    if (!f)
        fail_msg("cannot open %s (tests run from the repository root)", path);
    char line[1024];
    int found = 0;
    while (!found && fgets(line, sizeof line, f)) {
        if (strncmp(line, prefix, strlen(prefix)) != 0)
            continue;
        char *hash = strstr(line, " #");
        if (hash)
            *hash = '\0';
        size_t n = strcspn(line, "\n");
        while (n > 0 && (line[n - 1] == ' ' || line[n - 1] == '\t'))
            n--;
        line[n] = '\0';
        snprintf(out, cap, "%s", line);
        found = 1;
    }
    fclose(f);
    return found;
}

static void test_ci_runs_the_readme_test_command(void **state) {
    (void)state;
    char readme[1024], ci[1024];
    /* the README's test command: the line of its first block that runs make test */
    assert_true(first_line("README.md", "make deps && make test", readme, sizeof readme));
    assert_true(first_line(".ci/run", "make ", ci, sizeof ci));
    if (strcmp(readme, ci) != 0)
        fail_msg("README.md says '%s' but .ci/run runs '%s'", readme, ci);
    /* and nothing else runs make in .ci/run (one make line) */
    FILE *f = fopen(".ci/run", "r");
    assert_non_null(f);
    char line[1024];
    int makes = 0;
    while (fgets(line, sizeof line, f))
        makes += strncmp(line, "make", 4) == 0;
    fclose(f);
    assert_int_equal(makes, 1);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ci_runs_the_readme_test_command),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
