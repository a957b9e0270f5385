/* boundary.mode = still (solver/modes/bc_still.c): walls and base that never move, for what
 * deforms the assembly from inside the box (a regional tilt, a spreading substrate).
 *   still-1: a parameter file names it; no boundary moves, so the run's clock is time (the
 *            display interval in seconds, increments labelled by time) and the summary says
 *            the walls and the base are fixed.
 *   still-2: a run with a regional tilt ([tilt] angle = 10) keeps every wall and base element
 *            where it was built, bit for bit, while the free elements move; the boundary
 *            displacement stays 0. */
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
#include "summary.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char still_file[] = "[assembly]\n"
                                 "height = 2.5\n"
                                 "[time]\n"
                                 "equilibration = 200\n"
                                 "runtime = 300\n"
                                 "display_interval = 50\n"
                                 "[boundary]\n"
                                 "mode = still\n"
                                 "[tilt]\n"
                                 "angle = 10\n"
                                 "[output]\n"
                                 "checkpoint_interval = 0\n";

static cdem_params still_params(void) {
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    if (cdem_params_parse_text(&p, still_file, "still.ini", &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    return p;
}

/* still-1 */
static void test_bc_still_is_a_users_mode_on_the_clock_of_time(void **state) {
    (void)state;
    const cdem_params p = still_params();
    assert_int_equal(p.mode, CDEM_MODE_STILL);
    assert_true(CDEM_MODE_STILL < CDEM_MODE_WORDS); /* a users' mode, not a fixture */
    assert_int_equal(cdem_mode_clock_of(p.mode), CDEM_CLOCK_TIME);
    cdem_error err;
    assert_int_equal(cdem_run_validate(&p, &err), CDEM_OK);
    cdem_model m;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    assert_int_equal(m.mode.moving_boundaries, 0);
    char *text = NULL;
    assert_int_equal(cdem_summary_text(&p, &m, 100, 10, 1, &text, &err), CDEM_OK);
    assert_non_null(strstr(text, "  mode:                        still\n"));
    assert_non_null(strstr(text, "walls and base:              fixed for the whole run"));
    assert_non_null(strstr(text, "display interval:            50 s"));
    assert_non_null(strstr(text, "Regional tilt"));
    free(text);
}

/* still-2 */
static void test_bc_still_walls_stay_while_the_tilt_moves_the_pile(void **state) {
    (void)state;
    const cdem_params p = still_params();
    cdem_error err;
    cdem_run_ctx *r = NULL;
    if (cdem_run_open(&p, &quiet_run, NULL, &r, &err) != CDEM_OK)
        fail_msg("cdem_run_open: %s", err.msg);
    cdem_snapshot *before = capture(r);
    assert_int_equal(cdem_run_advance(r, cdem_run_total_steps(r), &err), CDEM_OK);
    cdem_snapshot *after = capture(r);
    size_t n0 = 0, n1 = 0;
    const uint32_t *flags = array_n(before, "state.flags", &n0);
    const int32_t *id0 = array_n(before, "state.id", NULL), *id1 = array_n(after, "state.id", &n1);
    const double *x0 = array_n(before, "state.x", NULL), *y0 = array_n(before, "state.y", NULL);
    const double *x1 = array_n(after, "state.x", NULL), *y1 = array_n(after, "state.y", NULL);
    size_t walls = 0, free_moved = 0;
    for (size_t i = 0; i < n0; i++) {
        size_t j = 0; /* the same element after */
        while (j < n1 && id1[j] != id0[i])
            j++;
        if (j == n1)
            continue; /* an escaped free element */
        if (flags[i] & CDEM_FLAGS_BOUNDARY) {
            walls++;
            if (x1[j] != x0[i] || y1[j] != y0[i])
                fail_msg("boundary element %d moved (%.17g, %.17g) -> (%.17g, %.17g)", (int)id0[i],
                         x0[i], y0[i], x1[j], y1[j]);
        } else {
            free_moved += hypot(x1[j] - x0[i], y1[j] - y0[i]) > 1.0;
        }
    }
    assert_true(walls > 50);
    assert_true(free_moved > 100); /* the pile settled and leaned: the test sees motion */
    cdem_snapshot_free(before);
    cdem_snapshot_free(after);
    assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_still_is_a_users_mode_on_the_clock_of_time),
        cmocka_unit_test(test_bc_still_walls_stay_while_the_tilt_moves_the_pile),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
