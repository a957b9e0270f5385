/* Every "section.key = value" that a message or help text of the programs tells the user to
 * set (e.g. "run with physics.calculate_stress = on") is a value the parameter parser
 * accepts, spelled the way the docs and --print-defaults spell it. Issue 18 found an error
 * hint saying "calculate_stress = true" where everything else says "on". The sources are
 * scanned (common/, solver/, analysis/; run from the repository root), so a new hint is
 * checked without editing this test. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "params.h"

#include <ctype.h>
#include <glob.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scratch.h"

static const char *const sections[] = {"assembly",      "time",     "physics", "material",
                                       "heterogeneity", "boundary", "surface", "output"};

/* Checks one hint "section.key = value" found at text (file for messages); returns 1 when
 * it was a hint (a known section). */
static int check_hint(const char *at, const char *file) {
    char section[32], key[64], value[128];
    if (sscanf(at, "%31[a-z].%63[a-z0-9_] = %127[A-Za-z0-9_.+-]", section, key, value) != 3)
        return 0;
    size_t n = strlen(value);
    while (n > 0 && value[n - 1] == '.')
        value[--n] = '\0'; /* the full stop of the sentence */
    int known = 0;
    for (size_t k = 0; k < sizeof sections / sizeof sections[0]; k++)
        known |= !strcmp(section, sections[k]);
    if (!known)
        return 0;
    const cdem_param_def *def = cdem_params_find(section, key);
    if (!def)
        fail_msg("%s: hint '%s.%s = %s' names no parameter", file, section, key, value);
    cdem_params p;
    cdem_params_defaults(&p);
    char assign[256];
    snprintf(assign, sizeof assign, "%s.%s=%s", section, key, value);
    cdem_error err;
    if (cdem_params_override(&p, assign, &err) != CDEM_OK)
        fail_msg("%s: hint '%s.%s = %s' is refused by the parser: %s", file, section, key, value,
                 err.msg);
    char canon[256];
    cdem_params_format_value(&p, def, canon, sizeof canon);
    if (strcmp(canon, value) != 0)
        fail_msg("%s: hint '%s.%s = %s' is spelled '%s' by --print-defaults and the docs", file,
                 section, key, value, canon);
    return 1;
}

static void test_hints_in_messages_are_valid_values(void **state) {
    (void)state;
    glob_t g;
    assert_int_equal(glob("common/*.c", 0, NULL, &g), 0);
    assert_int_equal(glob("common/h5/*.c", GLOB_APPEND, NULL, &g), 0);
    assert_int_equal(glob("solver/*.c", GLOB_APPEND, NULL, &g), 0);
    assert_int_equal(glob("solver/*/*.c", GLOB_APPEND, NULL, &g), 0);
    assert_int_equal(glob("analysis/*/*.c", GLOB_APPEND, NULL, &g), 0);
    int hints = 0;
    for (size_t i = 0; i < g.gl_pathc; i++) {
        char *text = scratch_read_file(g.gl_pathv[i]);
        assert_non_null(text);
        for (const char *s = text; *s; s++)
            if (islower((unsigned char)*s) && (s == text || !isalnum((unsigned char)s[-1])))
                hints += check_hint(s, g.gl_pathv[i]);
        free(text);
    }
    globfree(&g);
    assert_true(hints >= 3); /* the stress hints and the checkpoint hint at least */
}

/* The checker itself refuses the spelling the issue found. */
static void test_hints_checker_refuses_true_for_on(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    const cdem_param_def *def = cdem_params_find("physics", "calculate_stress");
    assert_non_null(def);
    cdem_error err;
    if (cdem_params_override(&p, "physics.calculate_stress=true", &err) == CDEM_OK) {
        char canon[64];
        cdem_params_format_value(&p, def, canon, sizeof canon);
        assert_string_not_equal(canon, "true"); /* accepted, but not how it is written */
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hints_in_messages_are_valid_values),
        cmocka_unit_test(test_hints_checker_refuses_true_for_on),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
