/* The tests' process fixture (solver/test_drag/process_test_drag.c): a uniform drag field
 * F = -rate m v, registered by its folder and its row in common/processes.def alone
 * (issue 45: a process is a plug-in). No parameter turns it on; the test adds it to a run's
 * processes, configures it on a stepper and steps three elements in free flight (no
 * contact, no gravity, no other damping): each velocity decays as exp(-rate t).
 *   drag-1: the decay over 40 s (two time constants) within 0.1 % at every 100 steps;
 *   drag-2: the summary loop writes its section; no parameter set turns it on. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "integrate.h"
#include "process.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RATE 0.05 /* 1/s, the fixture's */

/* drag-1 */
static void test_process_test_drag_decay(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    p.damping_mode = CDEM_DAMPING_CONTACT;
    p.contact_damping = 0.0;
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_state s;
    assert_int_equal(cdem_state_init(&s, 16, 0, &err), CDEM_OK);
    const double v0[3][2] = {{1.0, 0.0}, {0.0, 2.0}, {-3.0, 1.0}};
    for (int k = 0; k < 3; k++) { /* 5 km apart: never touching */
        size_t at = 0;
        assert_int_equal(
            cdem_state_append(&s, -1, 5000.0 * k, 0.0, m.radius[1], m.mass[1], 1, 0, 0, &at, &err),
            CDEM_OK);
        s.vx[at] = v0[k][0];
        s.vy[at] = v0[k][1];
    }
    cdem_integrator it;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    it.loads.gravity = 0.0;
    cdem_loads_set_gravity(&it.loads, 0.0, 0.0);
    it.damping_factor = 0.0; /* no absolute damping: the drag field alone */
    it.equilibrating = 0;
    cdem_processes ps;
    memset(&ps, 0, sizeof ps);
    assert_int_equal(cdem_processes_add(&ps, cdem_process_test_drag, &err), CDEM_OK);
    assert_int_equal(cdem_processes_configure(&ps, &p, &m, &it, &err), CDEM_OK);
    assert_true(cdem_viscous_active(&it.viscous));
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    const long steps = lround(40.0 / m.dt);
    for (long n = 1; n <= steps; n++) {
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        if (n % 100 != 0 && n != steps)
            continue;
        const double decay = exp(-RATE * (double)n * m.dt);
        for (size_t i = 0; i < s.n; i++) {
            const int k = (int)s.id[i];
            const double vx = v0[k][0] * decay, vy = v0[k][1] * decay;
            if (fabs(s.vx[i] - vx) > 1e-3 * fabs(v0[k][0]) + 1e-12 ||
                fabs(s.vy[i] - vy) > 1e-3 * fabs(v0[k][1]) + 1e-12)
                fail_msg("step %ld, element %d: velocity (%.9g, %.9g), exp(-rate t) gives "
                         "(%.9g, %.9g)",
                         n, k, s.vx[i], s.vy[i], vx, vy);
        }
    }
    cdem_integrator_free(&it);
    cdem_processes_free(&ps);
    cdem_state_free(&s);
}

/* drag-2 */
static void test_process_test_drag_registered_not_offered(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    assert_int_equal(cdem_process_test_drag->active(&p), 0);
    cdem_processes ps;
    cdem_error err;
    assert_int_equal(cdem_processes_init(&ps, &p, &err), CDEM_OK);
    assert_int_equal(ps.n, 0); /* the defaults turn no process on */
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    cdem_process_test_drag->describe(&p, NULL, f);
    fclose(f);
    assert_string_equal(text, "\nTest drag\n  rate: 0.05 1/s\n");
    free(text);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_process_test_drag_decay),
        cmocka_unit_test(test_process_test_drag_registered_not_offered),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
