/* Tests of common/suggest: the one edit distance of the programs' "did you mean" (case
 * ignored, names cut at 63 characters), the closeness rule, and the choice of a name. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "suggest.h"

#include <string.h>

/* suggest-1: distances, the case rule and the 63-character cut. */
static void test_suggest_distance(void **state) {
    (void)state;
    static const struct {
        const char *a, *b;
        size_t d;
    } cases[] = {
        {"", "", 0},
        {"render", "render", 0},
        {"rendr", "render", 1},
        {"RENDER", "render", 0},
        {"Width", "width", 0},
        {"kitten", "sitting", 3},
        {"", "abc", 3},
        {"--thread", "--threads", 1},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        assert_int_equal(cdem_edit_distance(cases[i].a, cases[i].b), cases[i].d);
    char a[100], b[100];
    memset(a, 'x', 99);
    memset(b, 'x', 99);
    a[99] = b[99] = '\0';
    b[80] = 'y'; /* beyond the 63 compared characters */
    assert_int_equal(cdem_edit_distance(a, b), 0);
}

/* suggest-2: a name is offered within a third of the word's length, at least 2. */
static void test_suggest_close(void **state) {
    (void)state;
    assert_true(cdem_suggest_close(2, "ab"));
    assert_false(cdem_suggest_close(3, "abcdefgh"));
    assert_true(cdem_suggest_close(3, "abcdefghi"));
    assert_false(cdem_suggest_close(4, "abcdefghi"));
}

/* suggest-3: the nearest name (the first of equals), or none when all are far. */
static void test_suggest_choice(void **state) {
    (void)state;
    static const char *const names[] = {"info", "render", "series", "repose"};
    assert_string_equal(cdem_suggest("rendr", names, 4), "render");
    assert_string_equal(cdem_suggest("Serie", names, 4), "series");
    assert_string_equal(cdem_suggest("repos", names, 4), "repose");
    assert_null(cdem_suggest("frobnicate", names, 4));
    assert_null(cdem_suggest("info", names, 0));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_suggest_distance),
        cmocka_unit_test(test_suggest_close),
        cmocka_unit_test(test_suggest_choice),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
