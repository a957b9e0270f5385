/* bc_still: boundary.mode = still. The walls and the base are built as for every mode and
 * never move; nothing is removed. What deforms the assembly acts inside the box: a regional
 * tilt turning gravity ([tilt], solver/tilt/) or a viscous substrate spreading under its
 * load ([salt], solver/salt/), alone the assembly only settles. With no moving boundary the
 * run's clock is its time (derive: moving_boundaries = 0, so time.display_interval is in
 * seconds and the increments are labelled by time, as in the repose mode); the run's boundary
 * displacement stays 0. This is the set-up of gravity gliding on a tilted margin (docs/solver.md,
 * "Regional tilt"). tests/test_bc_still.c runs it. */
#include "bc.h"
#include "summary_line.h"

typedef struct {
    char unused; /* nothing evolves: a context only because every mode has one */
} still_ctx;

static cdem_status still_init(void *ctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                              cdem_error *err) {
    (void)ctx, (void)p, (void)m, (void)s, (void)err;
    return CDEM_OK;
}

static cdem_status still_apply(void *ctx, cdem_state *s, long k, double du, double dt,
                               cdem_error *err) {
    (void)ctx, (void)s, (void)k, (void)du, (void)dt, (void)err;
    return CDEM_OK;
}

static double still_net(const void *ctx) {
    (void)ctx;
    return 0.0;
}

static void still_view(const void *ctx, FILE *out) {
    (void)ctx;
    fprintf(out, "Boundary mode: still: walls and base fixed; the deformation is driven from "
                 "inside the box.\n");
}

static void still_derive(const cdem_params *p, cdem_model_mode *out) {
    (void)p;
    out->moving_boundaries = 0;
    out->still = "walls and base fixed; the assembly deforms under what acts inside the box "
                 "(a tilt, a spreading substrate) or only settles";
}

static void still_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    (void)p, (void)m;
    cdem_summary_line(out, "walls and base", "fixed for the whole run");
}

static cdem_status still_save(const void *ctx, cdem_snapshot *snap, cdem_error *err) {
    (void)ctx, (void)snap, (void)err;
    return CDEM_OK; /* nothing evolves: a resumed run is the same mode */
}

static cdem_status still_restore(void *ctx, const cdem_snapshot *snap, cdem_error *err) {
    (void)ctx, (void)snap, (void)err;
    return CDEM_OK;
}

static const cdem_bc_ops still_ops = {
    .state_size = sizeof(still_ctx),
    .init = still_init,            /* nothing to add or flag */
    .apply = still_apply,          /* moves nothing */
    .net_displacement = still_net, /* 0 */
    .view = still_view,
    .derive = still_derive,     /* no moving boundary: the clock is time */
    .describe = still_describe, /* its summary line */
    .save = still_save,         /* nothing evolves: resumes bit-identically */
    .restore = still_restore,
};

const cdem_bc_ops *const cdem_bc_still = &still_ops;
