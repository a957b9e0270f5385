/* fuzz_util: helpers shared by the fuzz harnesses in tests/fuzz/ (temporary folders and
 * files for readers that take a path, and the invariant check that turns a broken
 * post-condition into a crash libFuzzer reports).
 * Ownership: every helper cleans up what it created; paths are caller buffers.
 * Thread safety: reentrant (no shared state). The harnesses are also compiled, with the
 * normal compiler and without libFuzzer, into tests/test_fuzz_corpus.c, which replays the
 * regression corpus tests/fuzz/corpus/<harness>/ in `make test`. */
#ifndef CDEM_FUZZ_UTIL_H
#define CDEM_FUZZ_UTIL_H

#include <dirent.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Stops the process with a message when a post-condition of the code under test fails
 * (libFuzzer and the replay driver both report the abort as a failure). */
#define FUZZ_CHECK(cond)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: fuzz invariant failed: %s\n", __FILE__, __LINE__, #cond);      \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

/* Creates a fresh private folder under $TMPDIR (or /tmp) into dir (>= 256 bytes).
 * Returns 0 on success. */
static inline int fuzz_mkdtemp(char *dir, size_t cap) {
    const char *t = getenv("TMPDIR");
    snprintf(dir, cap, "%s/cdem-fuzz-XXXXXX", t && *t ? t : "/tmp");
    return mkdtemp(dir) ? 0 : -1;
}

/* Writes n bytes to path; returns 0 on success. */
static inline int fuzz_write_file(const char *path, const void *data, size_t n) {
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    size_t w = n ? fwrite(data, 1, n, f) : 0;
    int bad = fclose(f) != 0 || w != n;
    return bad ? -1 : 0;
}

/* Removes every plain file in dir, then dir itself (the harness folders are flat). */
static inline void fuzz_rmdir(const char *dir) {
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char path[1024];
        while ((e = readdir(d)) != NULL) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
                continue;
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
        closedir(d);
    }
    rmdir(dir);
}

/* malloc'd NUL-terminated copy of data (NULL when out of memory). */
static inline char *fuzz_strndup(const uint8_t *data, size_t n) {
    char *s = malloc(n + 1);
    if (s) {
        if (n)
            memcpy(s, data, n);
        s[n] = '\0';
    }
    return s;
}

#endif
