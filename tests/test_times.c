/* The times the docs quote for the README's commands come from docs/times.md, the page
 * `make times` generates by timing each command on a fresh clone (scripts/time_fresh_clone.sh,
 * with the machine, the date and the load). Issue 35: "half a minute" for `make demo` (1.5
 * minutes measured on a fresh clone), "a few minutes" for `make -C examples quick` (the
 * examples' README said 40). Every "`COMMAND` took T" in the checked files must be the
 * page's time for COMMAND, and the old unmeasured phrases must be gone.
 * Runs from the repository root. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The files that quote times of the README's commands. */
static const char *const QUOTING[] = {"README.md", "docs/guide.md", "examples/README.md",
                                      "examples/Makefile", NULL};

/* Time claims that were never measured (the list). */
static const char *const VAGUE[] = {"half a minute", "a few minutes", "several minutes", NULL};

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

typedef struct {
    char command[128]; /* make demo */
    char shown[64];    /* 17 s, 1.5 min */
} timed;

/* The rows "| `COMMAND` | SHOWN | ..." of docs/times.md; returns their number. */
static int read_times(timed *rows, int max) {
    char *page = slurp("docs/times.md");
    assert_non_null(page);
    int n = 0;
    for (char *line = strtok(page, "\n"); line && n < max; line = strtok(NULL, "\n")) {
        if (strncmp(line, "| `", 3) != 0)
            continue;
        const char *c = line + 3, *ce = strchr(c, '`');
        const char *s = ce ? strstr(ce, "| ") : NULL;
        const char *se = s ? strstr(s + 2, " |") : NULL;
        if (!se)
            continue;
        snprintf(rows[n].command, sizeof rows[n].command, "%.*s", (int)(ce - c), c);
        snprintf(rows[n].shown, sizeof rows[n].shown, "%.*s", (int)(se - s - 2), s + 2);
        n++;
    }
    free(page);
    return n;
}

static void test_times_quoted_from_the_page(void **unused) {
    (void)unused;
    timed rows[16];
    const int n = read_times(rows, 16);
    assert_true(n >= 3); /* make demo, make test, make asan at least */
    static char report[8192];
    report[0] = '\0';
    int bad = 0, quotes = 0;
    for (size_t d = 0; QUOTING[d]; d++) {
        char *text = slurp(QUOTING[d]);
        assert_non_null(text);
        for (int r = 0; r < n; r++) {
            char key[256];
            snprintf(key, sizeof key, "`%.127s` took ", rows[r].command);
            for (const char *hit = strstr(text, key); hit; hit = strstr(hit + 1, key)) {
                const char *t = hit + strlen(key);
                quotes++;
                if (strncmp(t, rows[r].shown, strlen(rows[r].shown)) != 0) {
                    const size_t o = strlen(report);
                    snprintf(report + o, sizeof report - o,
                             "\n  %s: `%s` took %.12s..., docs/times.md says %s", QUOTING[d],
                             rows[r].command, t, rows[r].shown);
                    bad++;
                }
            }
        }
        for (size_t v = 0; VAGUE[v]; v++) {
            const char *hit = strstr(text, VAGUE[v]);
            if (hit) {
                const size_t o = strlen(report);
                snprintf(report + o, sizeof report - o, "\n  %s: '%.60s' (not measured)",
                         QUOTING[d], hit);
                bad++;
            }
        }
        free(text);
    }
    if (bad)
        fail_msg("%d time claims differ from docs/times.md (make times):%s", bad, report);
    /* the README quotes the first two commands a newcomer runs */
    char *readme = slurp("README.md");
    assert_non_null(readme);
    const int demo = strstr(readme, "`make demo` took ") != NULL;
    const int test = strstr(readme, "`make test` took ") != NULL;
    free(readme);
    if (!demo || !test)
        fail_msg("README.md does not quote the measured times of make demo and make test");
    printf("    %d quoted times match docs/times.md\n", quotes);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_times_quoted_from_the_page),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
