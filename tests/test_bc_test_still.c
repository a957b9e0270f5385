/* The tests' mode fixture (solver/modes/bc_test_still.c): a mode with only the hooks every
 * mode must have, registered by its file and its row in common/modes.def alone. It runs
 * through the staged run interface with the interface's defaults (the model's mode part, the
 * summary, the parameter rules), and no parameter file can name it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "run.h"
#include "summary.h"

#include <stdlib.h>
#include <string.h>

/* A small default model in the fixture mode. */
static cdem_params still_params(void) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_TEST_STILL;
    p.height = 2.5;
    p.equilibration = 100;
    p.runtime = 150;
    p.checkpoint_interval = 0;
    return p;
}

/* mode-fixture-1: the defaults of a mode without the optional hooks. */
static void test_bc_test_still_defaults(void **state) {
    (void)state;
    const cdem_params p = still_params();
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    assert_true(m.gravity == p.gravity);
    assert_int_equal(m.mode.moving_boundaries, 1);
    assert_null(m.mode.input);
    char buf[CDEM_ERROR_MSG_MAX];
    cdem_rule_log log = {buf, sizeof buf, 0, 0};
    cdem_bc_rules(&p, &log);
    assert_int_equal(log.count, 0);
    char *text = NULL;
    assert_int_equal(cdem_summary_text(&p, &m, 100, 10, 1, &text, &err), CDEM_OK);
    const char *mode = strstr(text, "  mode:");
    assert_non_null(mode);
    assert_non_null(strstr(mode, "test-still\n\nMaterial\n")); /* no lines of its own */
    free(text);
}

/* mode-fixture-2: a run in it completes, and nothing moved the boundary. */
static void test_bc_test_still_runs(void **state) {
    (void)state;
    const cdem_params p = still_params();
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.quiet = 1; /* in memory: no file */
    cdem_run_ctx *r = NULL;
    cdem_error err;
    if (cdem_run_open(&p, &o, NULL, &r, &err) != CDEM_OK)
        fail_msg("cdem_run_open: %s", err.msg);
    const long total = cdem_run_total_steps(r);
    assert_int_equal(cdem_run_advance(r, total, &err), CDEM_OK);
    assert_int_equal(cdem_run_current_step(r), total);
    assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
}

/* mode-fixture-3: no parameter file can choose it, and a parameter set holding it is
 * refused. */
static void test_bc_test_still_not_offered(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    assert_true(CDEM_MODE_TEST_STILL >= CDEM_MODE_WORDS);
    assert_int_equal(cdem_params_override(&p, "boundary.mode=test-still", &err), CDEM_ERR_RANGE);
    const char *list = strstr(err.msg, "must be one of ");
    assert_non_null(list);
    assert_null(strstr(list, "test-still"));
    p.mode = CDEM_MODE_TEST_STILL;
    assert_int_equal(cdem_run_validate(&p, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "[boundary] mode"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_test_still_defaults),
        cmocka_unit_test(test_bc_test_still_runs),
        cmocka_unit_test(test_bc_test_still_not_offered),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
