/* test_bad_input: one named regression test per defect the fuzzers found (tests/fuzz/,
 * docs/reliability.md "Bad input"), asserting the fixed behaviour and its message. The raw
 * crashing inputs are also replayed by test_fuzz_corpus. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "cdem2d.h"
#include "fault_file.h"
#include "h5format.h"
#include "params.h"
#include "scratch.h"

#include <sys/stat.h>
#include <unistd.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* fuzz_params, crash-roundtrip-quote-in-string: a string value with a '"' inside was
 * accepted, but cdem_params_write then wrote a line that does not parse back (so a run's
 * stored parameters or --print-defaults output could not be reused). Now refused, naming
 * the file, line, key and character; a value quoted as a whole still works. */
static void test_bad_input_params_quote_inside_string_value(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_error err;
    cdem_error_clear(&err);
    const char *text = "[boundary]\nmode = irregular-fault\nfault_file = a\"b.txt\n";
    assert_int_equal(cdem_params_parse_text(&p, text, "model.ini", &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "model.ini:3"));
    assert_non_null(strstr(err.msg, "fault_file"));
    assert_non_null(strstr(err.msg, "character 2"));
    assert_non_null(strstr(err.msg, "a quote"));
    /* a control character (form feed) inside the value */
    cdem_error_clear(&err);
    assert_int_equal(cdem_params_parse_text(&p, "[output]\nprefix = a\fb\n", "m.ini", &err),
                     CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "m.ini:2"));
    assert_non_null(strstr(err.msg, "control character"));
    /* the same through an override */
    assert_int_equal(cdem_params_override(&p, "output.prefix=x\"y", &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "prefix"));
    /* quoted as a whole, '#' and edge spaces are kept and written back the same */
    assert_int_equal(cdem_params_parse_text(&p, "[output]\nprefix = \" run #1 \"\n", "m.ini", &err),
                     CDEM_OK);
    assert_string_equal(p.prefix, " run #1 ");
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    cdem_params_write(&p, f);
    fclose(f);
    cdem_params q;
    cdem_params_defaults(&q);
    assert_int_equal(cdem_params_parse_text(&q, buf, "written.ini", &err), CDEM_OK);
    assert_string_equal(q.prefix, " run #1 ");
    free(buf);
}

static void tmp_dir(char *buf, size_t n, const char *name) {
    scratch_path(buf, n, name);
    mkdir(buf, 0777);
}

static void write_bytes(const char *path, const char *data, size_t n) {
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

/* Review of the fuzzed readers: a NUL byte ended a fault-file line early without notice
 * (fgets + strlen), so "1400 0<NUL>junk" read as "1400 0". Now refused with its offset. */
static void test_bad_input_fault_file_nul_byte(void **state) {
    (void)state;
    char dir[1024], path[1100];
    tmp_dir(dir, sizeof dir, "fault");
    snprintf(path, sizeof path, "%s/fault.txt", dir);
    static const char data[] = "1400 0\n1300 500\0 junk\n1200 900\n";
    write_bytes(path, data, sizeof data - 1);
    cdem_fault_polyline pl;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_fault_file_read(path, 1400.0, 25.0, &pl, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, "byte 16 is a NUL byte"));
    assert_int_equal(pl.n, 0);
    remove(path);
    rmdir(dir);
}

static cdem_status count_sink(void *user, const cdem_increment_info *info, const cdem_state *s,
                              cdem_error *err);

/* fuzz_fault_file (issue 19's make fuzz run): "0,0x1p-1074" read as a vertex 4.9e-324 m
 * above the base, 1400 m to the left: the first segment was flat, and the fault's x below
 * the base (extrapolated along it) came out infinite. Hexadecimal numbers are refused now,
 * and so is a segment dipping less than CDEM_FAULT_MIN_DIP in decimal (1e-300). */
static void test_bad_input_fault_file_flat_segment(void **state) {
    (void)state;
    char dir[1024], path[1100];
    tmp_dir(dir, sizeof dir, "fault_flat");
    snprintf(path, sizeof path, "%s/fault.txt", dir);
    static const struct {
        const char *text; /* the file */
        const char *want; /* in the message */
    } bad[] = {
        {"1399, 0\n0,0x1p-1074", "line 2: '0,0x1p-1074': field 2 is not a number"},
        {"1400 0\n0 1e-300\n", "line 2: the segment from (1400, 0) m to (0, 1e-300) m dips"},
        {"1400 0\n1000 5\n", "dips 0.716 degrees; every segment must dip at least 1 degrees"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        write_bytes(path, bad[k].text, strlen(bad[k].text));
        cdem_fault_polyline pl;
        cdem_error err;
        cdem_error_clear(&err);
        assert_int_not_equal(cdem_fault_file_read(path, 1400.0, 25.0, &pl, &err), CDEM_OK);
        if (!strstr(err.msg, bad[k].want) || !strstr(err.msg, path))
            fail_msg("case %zu: %s", k, err.msg);
        assert_int_equal(pl.n, 0);
    }
    remove(path);
    rmdir(dir);
}

/* fuzz_cdem2d (issue 19's make fuzz run): modelresults_0.txt and modelresults_00.txt were
 * both imported as increment 0, two increments with one number. Refused now, naming both. */
static void test_bad_input_cdem2d_duplicate_increment_number(void **state) {
    (void)state;
    char dir[1024], p0[1100], p00[1100];
    tmp_dir(dir, sizeof dir, "cdem2d_dup");
    snprintf(p0, sizeof p0, "%s/modelresults_0.txt", dir);
    snprintf(p00, sizeof p00, "%s/modelresults_00.txt", dir);
    static const char data[] = "100 100 50 1\n";
    write_bytes(p0, data, sizeof data - 1);
    write_bytes(p00, data, sizeof data - 1);
    int calls = 0;
    cdem_cdem2d_meta meta;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_cdem2d_import(dir, count_sink, &calls, &meta, &err), CDEM_ERR_PARSE);
    cdem_cdem2d_meta_free(&meta);
    assert_int_equal(calls, 0);
    assert_non_null(strstr(err.msg, dir));
    assert_non_null(strstr(err.msg, "two results files for increment 0"));
    remove(p0);
    remove(p00);
    rmdir(dir);
}

static cdem_status count_sink(void *user, const cdem_increment_info *info, const cdem_state *s,
                              cdem_error *err) {
    (void)info;
    (void)s;
    (void)err;
    (*(int *)user)++;
    return CDEM_OK;
}

/* Review of the fuzzed readers: the cdem2D reader reads a whole file as one C string, so a
 * NUL byte silently dropped every row after it. Now refused, naming the file and offset. */
static void test_bad_input_cdem2d_nul_byte(void **state) {
    (void)state;
    char dir[1024], path[1100];
    tmp_dir(dir, sizeof dir, "cdem2d");
    snprintf(path, sizeof path, "%s/modelresults_0.txt", dir);
    static const char data[] = "100 100 50 1\n200 100 50 1\n\0"
                               "300 100 50 1\n";
    write_bytes(path, data, sizeof data - 1);
    int calls = 0;
    cdem_cdem2d_meta meta;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_cdem2d_import(dir, count_sink, &calls, &meta, &err), CDEM_ERR_PARSE);
    cdem_cdem2d_meta_free(&meta);
    assert_int_equal(calls, 0);
    assert_non_null(strstr(err.msg, path));
    if (!strstr(err.msg, "byte 27 is a NUL byte"))
        fail_msg("%s", err.msg);
    remove(path);
    rmdir(dir);
}

/* Review of the fuzzed readers: radii so large that the id-matching grid cannot be built
 * failed with a message that named no file. Then it named the results file; now the row
 * with the radius is refused, naming the file and line. */
static void test_bad_input_cdem2d_huge_radius_names_file(void **state) {
    (void)state;
    char dir[1024], p0[1100], p1[1100];
    tmp_dir(dir, sizeof dir, "cdem2d_huge");
    snprintf(p0, sizeof p0, "%s/modelresults_0.txt", dir);
    snprintf(p1, sizeof p1, "%s/modelresults_1.txt", dir);
    static const char data[] = "0 0 1e308 1\n1 1 1 1\n";
    write_bytes(p0, data, sizeof data - 1);
    write_bytes(p1, data, sizeof data - 1);
    int calls = 0;
    cdem_cdem2d_meta meta;
    cdem_error err;
    cdem_error_clear(&err);
    cdem_status st = cdem_cdem2d_import(dir, count_sink, &calls, &meta, &err);
    cdem_cdem2d_meta_free(&meta);
    assert_int_not_equal(st, CDEM_OK);
    /* since issue 19 (item 8) the radius itself is refused, on its row */
    assert_int_equal(calls, 0);
    assert_non_null(strstr(err.msg, p0));
    assert_non_null(strstr(err.msg, ":1: radius 1e+308 must be > 0 and at most"));
    remove(p0);
    remove(p1);
    rmdir(dir);
}

/* Loads increment 0 of the regression-corpus file `name` and expects a format error whose
 * message contains needle. */
static void expect_h5_load_error(const char *name, const char *needle) {
    const char *c = getenv("CDEM_FUZZ_CORPUS");
    const char *d = getenv("CDEM_TEST_DATA");
    char path[1024];
    if (c && *c)
        snprintf(path, sizeof path, "%s/h5/%s", c, name);
    else
        snprintf(path, sizeof path, "%s/../fuzz/corpus/h5/%s", d && *d ? d : "tests/data", name);
    cdem_h5_reader *r = NULL;
    cdem_error err;
    cdem_error_clear(&err);
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s: %s", path, err.msg);
    cdem_state s = {0};
    assert_int_equal(cdem_h5_reader_load_increment(r, 0, &s, NULL, &err), CDEM_ERR_FORMAT);
    if (!strstr(err.msg, needle) || !strstr(err.msg, path))
        fail_msg("expected '%s' and the path in: %s", needle, err.msg);
    assert_int_equal(s.n, 0);
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
}

/* fuzz_h5: an increment whose datasets claim 2e9 elements (89 kB file, storage never
 * written: HDF5 would return fill values) made the reader allocate ~100 GB. Refused before
 * allocating: above 20 million elements, or with no stored data. */
static void test_bad_input_h5_forged_element_count(void **state) {
    (void)state;
    expect_h5_load_error("crash-oom-forged-length",
                         "claims 2000000000 elements; this reader refuses more than 20000000");
    expect_h5_load_error("crash-unwritten-storage",
                         "claims 1000000 elements but none was ever written");
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_input_params_quote_inside_string_value),
        cmocka_unit_test(test_bad_input_fault_file_nul_byte),
        cmocka_unit_test(test_bad_input_cdem2d_nul_byte),
        cmocka_unit_test(test_bad_input_cdem2d_huge_radius_names_file),
        cmocka_unit_test(test_bad_input_fault_file_flat_segment),
        cmocka_unit_test(test_bad_input_cdem2d_duplicate_increment_number),
        cmocka_unit_test(test_bad_input_h5_forged_element_count),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
