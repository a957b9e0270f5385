/* A mode that owns its parameter (issue 45, item 2), through the tests' mode fixture
 * solver/modes/bc_test_lift.c: its one key, boundary.test_lift_ratio, is declared in its own
 * file (common/modes/test_lift.h) and reaches the parameter table, the parser, the range
 * check, the record of a run file and the mode from there, with no line of common/params.c.
 *   lift-1: the row is the table's: its default fills cdem_params, -s sets it, a value out of
 *           its range is refused naming the key, the value and the range.
 *   lift-2: a fixture's key is listed nowhere a user reads (--print-defaults,
 *           docs/parameters.md) and a run file's record holds it only when set, reading back.
 *   lift-3: the mode runs with the value: over the deformation the base rises ratio times the
 *           boundary displacement (to round-off), and the lateral walls do not move. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "run.h"
#include "run_fixtures.h"
#include "snapshot.h"
#include "state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A small default model in the fixture mode (no file, no checkpoints written). */
static cdem_params lift_params(void) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_TEST_LIFT;
    p.height = 2.5;
    p.equilibration = 100;
    p.runtime = 150;
    p.checkpoint_interval = 0;
    return p;
}

/* What a writer of p prints (record: the run file's record), malloc'd. */
static char *written(const cdem_params *p, int record) {
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    if (record)
        cdem_params_write_record(p, f);
    else
        cdem_params_write(p, f);
    fclose(f);
    return buf;
}

/* lift-1 */
static void test_bc_test_lift_key_is_a_row(void **state) {
    (void)state;
    const cdem_param_def *d = cdem_params_find("boundary", "test_lift_ratio");
    assert_non_null(d);
    assert_int_equal(d->fixture, 1);
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    assert_true(p.test_lift_ratio == 0.5);
    assert_int_equal(cdem_params_override(&p, "boundary.test_lift_ratio=2.25", &err), CDEM_OK);
    assert_true(p.test_lift_ratio == 2.25);
    assert_int_equal(cdem_params_override(&p, "boundary.test_lift_ratio=11", &err), CDEM_ERR_RANGE);
    if (!strstr(err.msg, "test_lift_ratio") || !strstr(err.msg, "11") || !strstr(err.msg, "10"))
        fail_msg("the refusal does not name the key, the value and the range: %s", err.msg);
    assert_true(p.test_lift_ratio == 2.25); /* the refused value left it as it was */
}

/* lift-2 */
static void test_bc_test_lift_key_listed_nowhere(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    char *every = written(&p, 0), *record = written(&p, 1);
    assert_null(strstr(every, "test_lift_ratio"));
    assert_null(strstr(record, "test_lift_ratio"));
    free(every);
    free(record);
    char *md = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&md, &len);
    assert_non_null(f);
    cdem_params_write_markdown(f);
    fclose(f);
    assert_null(strstr(md, "test_lift_ratio"));
    assert_non_null(strstr(md, "fault_dip")); /* a user's mode key is listed */
    free(md);
    /* set: the record holds it, and reads back to the same value */
    p.test_lift_ratio = 0.125;
    record = written(&p, 1);
    assert_non_null(strstr(record, "test_lift_ratio = 0.125\n"));
    cdem_params back;
    cdem_error err;
    cdem_params_defaults(&back);
    if (cdem_params_parse_text(&back, record, "record", &err) != CDEM_OK)
        fail_msg("the record does not read back: %s", err.msg);
    assert_true(back.test_lift_ratio == 0.125);
    free(record);
}

/* lift-3 */
static void test_bc_test_lift_base_rises_by_its_ratio(void **state) {
    (void)state;
    cdem_params p = lift_params();
    cdem_error err;
    assert_int_equal(cdem_params_override(&p, "boundary.test_lift_ratio=2", &err), CDEM_OK);
    cdem_model m;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_run_ctx *r = NULL;
    if (cdem_run_open(&p, &quiet_run, NULL, &r, &err) != CDEM_OK)
        fail_msg("cdem_run_open: %s", err.msg);
    assert_int_equal(cdem_run_advance(r, m.equil_steps, &err), CDEM_OK);
    cdem_snapshot *before = capture(r);
    assert_int_equal(cdem_run_advance(r, cdem_run_total_steps(r), &err), CDEM_OK);
    cdem_snapshot *after = capture(r);
    size_t n = 0, n2 = 0;
    const uint32_t *flags = array_n(before, "state.flags", &n);
    const int32_t *id0 = array_n(before, "state.id", NULL), *id1 = array_n(after, "state.id", &n2);
    const double *x0 = array_n(before, "state.x", NULL), *y0 = array_n(before, "state.y", NULL);
    const double *x1 = array_n(after, "state.x", NULL), *y1 = array_n(after, "state.y", NULL);
    const double *net = array_n(after, "bc.net", NULL);
    assert_true(net[0] > 1.0); /* the run moved its boundary */
    const double rise = 2.0 * net[0];
    size_t base = 0, walls = 0;
    for (size_t i = 0; i < n; i++) {
        if (!(flags[i] & CDEM_FLAGS_BOUNDARY))
            continue;
        size_t j = 0; /* the same element after (walls are never removed) */
        while (j < n2 && id1[j] != id0[i])
            j++;
        assert_true(j < n2);
        if (flags[i] & CDEM_FLAG_BASE) {
            base++;
            if (fabs(y1[j] - y0[i] - rise) > 1e-9 * rise || x1[j] != x0[i])
                fail_msg("base element %d rose %.12g m, not 2 x %.12g m", (int)id0[i],
                         y1[j] - y0[i], net[0]);
        } else {
            walls++;
            assert_true(x1[j] == x0[i] && y1[j] == y0[i]);
        }
    }
    assert_true(base > 10 && walls > 10);
    cdem_snapshot_free(before);
    cdem_snapshot_free(after);
    assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_test_lift_key_is_a_row),
        cmocka_unit_test(test_bc_test_lift_key_listed_nowhere),
        cmocka_unit_test(test_bc_test_lift_base_rises_by_its_ratio),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
