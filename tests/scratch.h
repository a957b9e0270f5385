/* Scratch files of the tests: the one fixture every test file uses for its temporary
 * files, instead of a copy of the set-up in each.
 *
 * tests/run_tests.sh gives a test run one private folder, $CDEM_TEST_TMP, and removes it
 * afterwards; a test binary started by hand falls back to /tmp. scratch_path() names a
 * file there, prefixed with the process id so that two binaries (or two runs by hand)
 * never share a file. A test group that needs a folder of its own (the command-line tests
 * cd into it, or compare whole folders) uses scratch_setup / scratch_teardown as its
 * cmocka group fixture: a fresh mkdtemp folder, removed with its contents at the end.
 * Header-only: each test is one .c file linked against the libraries. */
#ifndef CDEM_TESTS_SCRATCH_H
#define CDEM_TESTS_SCRATCH_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The folder scratch files go to: $CDEM_TEST_TMP, or /tmp without it. */
__attribute__((unused)) static const char *scratch_root(void) {
    const char *t = getenv("CDEM_TEST_TMP");
    return t && t[0] ? t : "/tmp";
}

/* BUF = <scratch root>/<pid>_NAME. */
__attribute__((unused)) static void scratch_path(char *buf, size_t cap, const char *name) {
    snprintf(buf, cap, "%s/%d_%s", scratch_root(), (int)getpid(), name);
}

/* A private folder: dir is the absolute or root-relative path made by mkdtemp. */
typedef struct {
    char dir[1024];
} scratch_dir;

/* Makes a fresh folder <scratch root>/PREFIX_XXXXXX in D; 0 or -1. */
__attribute__((unused)) static int scratch_dir_make(scratch_dir *d, const char *prefix) {
    snprintf(d->dir, sizeof d->dir, "%s/%s_XXXXXX", scratch_root(), prefix);
    return mkdtemp(d->dir) ? 0 : -1;
}

/* Removes D's folder and everything in it; 0 or -1. */
__attribute__((unused)) static int scratch_dir_remove(const scratch_dir *d) {
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", d->dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* BUF = D's folder/NAME. */
__attribute__((unused)) static void scratch_dir_path(const scratch_dir *d, char *buf, size_t cap,
                                                     const char *name) {
    snprintf(buf, cap, "%s/%s", d->dir, name);
}

/* cmocka group fixture: *state becomes a scratch_dir (a fresh folder named after the
 * test binary's process); the teardown removes the folder and frees the state. */
__attribute__((unused)) static int scratch_setup(void **state) {
    scratch_dir *d = calloc(1, sizeof *d);
    if (!d || scratch_dir_make(d, "test") != 0) {
        free(d);
        return -1;
    }
    *state = d;
    return 0;
}

__attribute__((unused)) static int scratch_teardown(void **state) {
    scratch_dir *d = *state;
    int rc = d ? scratch_dir_remove(d) : 0;
    free(d);
    return rc;
}

/* The whole file at path (malloc'd, NUL-terminated; the caller frees it), or NULL when it
 * cannot be read. For the tests that read sources and pages. */
__attribute__((unused)) static char *scratch_read_file(const char *path) {
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

#endif
