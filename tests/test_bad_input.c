/* test_bad_input: one named regression test per defect the fuzzers found (tests/fuzz/,
 * docs/reliability.md "Bad input"), asserting the fixed behaviour and its message. The raw
 * crashing inputs are also replayed by test_fuzz_corpus. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "params.h"

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

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_input_params_quote_inside_string_value),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
