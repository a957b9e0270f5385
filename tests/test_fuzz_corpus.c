/* test_fuzz_corpus: replays the fuzz regression corpus tests/fuzz/corpus/<harness>/ through
 * the same entry functions libFuzzer drives (tests/fuzz/fuzz_*.c, compiled here with the
 * normal compiler and without libFuzzer, each LLVMFuzzerTestOneInput renamed). Every file
 * is an input that once crashed, hung, leaked or broke an invariant, or a seed covering a
 * distinct path; a regression aborts this binary (or trips the sanitizers under make asan).
 * The corpus root is $CDEM_FUZZ_CORPUS, else $CDEM_TEST_DATA/../fuzz/corpus. */
#define LLVMFuzzerTestOneInput cdem_fuzz_params_one
#include "fuzz/fuzz_params.c"
#undef LLVMFuzzerTestOneInput
#define LLVMFuzzerTestOneInput cdem_fuzz_fault_file_one
#include "fuzz/fuzz_fault_file.c"
#undef LLVMFuzzerTestOneInput
#define LLVMFuzzerTestOneInput cdem_fuzz_cdem2d_one
#include "fuzz/fuzz_cdem2d.c"
#undef LLVMFuzzerTestOneInput
#define LLVMFuzzerTestOneInput cdem_fuzz_h5_one
#include "fuzz/fuzz_h5.c"
#undef LLVMFuzzerTestOneInput

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <sys/stat.h>

#include <cmocka.h>

typedef int (*fuzz_entry)(const uint8_t *data, size_t size);

static void corpus_dir(char *buf, size_t n, const char *harness) {
    const char *c = getenv("CDEM_FUZZ_CORPUS");
    if (c && *c) {
        snprintf(buf, n, "%s/%s", c, harness);
        return;
    }
    const char *d = getenv("CDEM_TEST_DATA");
    snprintf(buf, n, "%s/../fuzz/corpus/%s", d && *d ? d : "tests/data", harness);
}

/* Feeds every regular file of the harness's corpus folder to entry; returns the count. */
static size_t replay(const char *harness, fuzz_entry entry) {
    char dir[1024], path[2048];
    corpus_dir(dir, sizeof dir, harness);
    DIR *d = opendir(dir);
    if (!d)
        fail_msg("cannot open the fuzz corpus folder %s", dir);
    size_t count = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat sb;
        if (stat(path, &sb) != 0 || !S_ISREG(sb.st_mode))
            continue;
        FILE *f = fopen(path, "rb");
        assert_non_null(f);
        uint8_t *buf = malloc((size_t)sb.st_size + 1);
        assert_non_null(buf);
        size_t got = fread(buf, 1, (size_t)sb.st_size, f);
        fclose(f);
        assert_int_equal(got, (size_t)sb.st_size);
        assert_int_equal(entry(buf, got), 0);
        free(buf);
        count++;
    }
    closedir(d);
    return count;
}

static void test_fuzz_corpus_params(void **state) {
    (void)state;
    assert_true(replay("params", cdem_fuzz_params_one) >= 5);
}

static void test_fuzz_corpus_fault_file(void **state) {
    (void)state;
    assert_true(replay("fault_file", cdem_fuzz_fault_file_one) >= 5);
}

static void test_fuzz_corpus_cdem2d(void **state) {
    (void)state;
    assert_true(replay("cdem2d", cdem_fuzz_cdem2d_one) >= 3);
}

static void test_fuzz_corpus_h5(void **state) {
    (void)state;
    assert_true(replay("h5", cdem_fuzz_h5_one) >= 2);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fuzz_corpus_params),
        cmocka_unit_test(test_fuzz_corpus_fault_file),
        cmocka_unit_test(test_fuzz_corpus_cdem2d),
        cmocka_unit_test(test_fuzz_corpus_h5),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
