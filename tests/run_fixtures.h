/* run_fixtures: runs in memory through the staged run interface (run.h) and the arrays of
 * their captured state, shared by the tests that follow a whole run of a mode or a process
 * (test_bc_test_tilt, test_bc_test_lift, test_bc_still, test_tilt). Header-only, static
 * functions, test code only; a failure fails the calling test with its message. */
#ifndef CDEM_TESTS_RUN_FIXTURES_H
#define CDEM_TESTS_RUN_FIXTURES_H

#include "run.h"
#include "snapshot.h"

/* In memory (no file), no log: a run keeps a pointer to its options, so they outlive it. */
static const cdem_run_options quiet_run = {.quiet = 1};

/* A run of p, fresh (resume NULL) or from a captured state. */
__attribute__((unused)) static cdem_run_ctx *open_run(const cdem_params *p,
                                                      const cdem_snapshot *resume) {
    cdem_run_ctx *r = NULL;
    cdem_error err;
    if (cdem_run_open(p, &quiet_run, resume, &r, &err) != CDEM_OK)
        fail_msg("cdem_run_open: %s", err.msg);
    return r;
}

/* The run's state now, as its checkpoint would hold it (the caller frees it). */
__attribute__((unused)) static cdem_snapshot *capture(const cdem_run_ctx *r) {
    cdem_snapshot *snap = NULL;
    cdem_error err;
    assert_int_equal(cdem_snapshot_alloc(&snap, &err), CDEM_OK);
    if (cdem_run_capture(r, snap, &err) != CDEM_OK)
        fail_msg("cdem_run_capture: %s", err.msg);
    return snap;
}

/* A captured array by name ("state.x", "bc.net", ...), its length in *count (may be NULL). */
__attribute__((unused)) static const void *array_n(const cdem_snapshot *s, const char *name,
                                                   size_t *count) {
    const cdem_snapshot_array *a = cdem_snapshot_get(s, name);
    if (!a)
        fail_msg("the checkpoint has no %s", name);
    if (count)
        *count = a->count;
    return a->data;
}

/* A captured array of doubles by name. */
__attribute__((unused)) static const double *array_of(const cdem_snapshot *s, const char *name) {
    return (const double *)array_n(s, name, NULL);
}

#endif
