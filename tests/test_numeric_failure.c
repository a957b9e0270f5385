/* test_numeric_failure: the NaN/Inf protection of cdem_run (issue 10). The scenario
 * is a time step made too large through keep_constants at a small unit scaling. In cdem-c
 * the time step always follows the smallest mass (dt = 0.25 sqrt(m_min / Kn), as in the original
 * program), so keep_constants at 100 m stays stable: the first test checks exactly that. The second
 * makes the time step 10x too large through the run's fault-injection option (dt_factor, standing
 * in for the original program's 1000 m time step with 100x lighter elements) on the same
 * model. Such a run does not reach NaN: elements fly out and are removed as escaping, and
 * before the instability guard of run.c it went on writing garbage. The test checks the run
 * stops with CDEM_ERR_NUMERIC and a message naming the element, the step, the likely cause
 * and keep_constants, and that the file records "numerical-failure" and still holds every
 * increment written before, all elements present with finite positions. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "h5format.h"
#include "params.h"
#include "run.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* 10 x 2.5 units at 100 m with keep_constants on: ~1400 elements. */
static void small_keep_constants(cdem_params *p) {
    cdem_params_defaults(p);
    p->height = 2.5;
    p->unit_scaling = 100.0;
    p->keep_constants = 1;
    p->runtime = 200.0;
    p->equilibration = 100.0;
    p->display_interval = 20.0;
}

/* Opens path and checks every increment loads with finite positions and the series reads;
 * returns the count. */
static size_t check_file(const char *path, const char *want_reason) {
    cdem_h5_reader *r = NULL;
    cdem_error err;
    cdem_error_clear(&err);
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("cannot open %s: %s", path, err.msg);
    assert_string_equal(cdem_h5_reader_stop_reason(r), want_reason);
    size_t n = cdem_h5_reader_increment_count(r);
    for (size_t k = 0; k < n; k++) {
        cdem_state s = {0};
        cdem_increment_info info;
        if (cdem_h5_reader_load_increment(r, k, &s, &info, &err) != CDEM_OK)
            fail_msg("increment %zu of %s: %s", k, path, err.msg);
        assert_true(s.n > 1000);
        for (size_t i = 0; i < s.n; i++)
            assert_true(isfinite(s.x[i]) && isfinite(s.y[i]));
        cdem_state_free(&s);
    }
    /* the writer never writes what the reader refuses (issue 35, item 7): the series of a
     * run that blew up reads back too */
    cdem_series_sample *q = NULL;
    size_t nq = 0;
    if (cdem_h5_reader_read_series(r, &q, &nq, &err) != CDEM_OK)
        fail_msg("the series of %s: %s", path, err.msg);
    assert_true(nq > 0);
    free(q);
    cdem_h5_reader_close(r);
    return n;
}

static void test_numeric_failure_keep_constants_small_scaling_is_stable(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "keep_stable.h5");
    cdem_params p;
    small_keep_constants(&p);
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    o.max_steps = 1500;
    cdem_error err;
    cdem_error_clear(&err);
    cdem_status st = cdem_run(&p, &o, &err);
    if (st != CDEM_OK)
        fail_msg("keep_constants at 100 m: %s", err.msg);
    assert_true(check_file(path, "stopped-early") >= 1);
    remove(path);
}

static void test_numeric_failure_time_step_too_large_stops_with_diagnosis(void **state) {
    (void)state;
    char path[1024];
    scratch_path(path, sizeof path, "blowup.h5");
    cdem_params p;
    small_keep_constants(&p);
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    o.max_steps = 20000; /* bound the test if the protection ever stops working */
    o.dt_factor = 10.0;  /* the 1000 m time step at 100 m: elements 10x lighter */
    cdem_error err;
    cdem_error_clear(&err);
    cdem_status st = cdem_run(&p, &o, &err);
    if (st != CDEM_ERR_NUMERIC)
        fail_msg("expected CDEM_ERR_NUMERIC, got %d: %s", (int)st, err.msg);
    /* which element, which step, the likely cause and what to change */
    assert_non_null(strstr(err.msg, "element id "));
    assert_non_null(strstr(err.msg, "at step "));
    assert_non_null(strstr(err.msg, "time step is too large"));
    assert_non_null(strstr(err.msg, "keep_constants = on"));
    /* the file says so and keeps the increments written before the blow-up */
    assert_true(check_file(path, "numerical-failure") >= 1);
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_non_null(strstr(cdem_h5_reader_stop_detail(r), "element id "));
    cdem_h5_reader_close(r);
    remove(path);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_numeric_failure_keep_constants_small_scaling_is_stable),
        cmocka_unit_test(test_numeric_failure_time_step_too_large_stops_with_diagnosis),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
