/* bc_test_still: a fixture of the tests, not a mode of the model (no parameter file can name
 * it: its row in common/modes.def is CDEM_TEST_MODE). Its walls never move. It fills only the
 * hooks every mode must have (bc.h), so the optional ones keep their defaults: no rules of its
 * own, gravity on and one boundary at the boundary speed in the model (cdem_model_mode_default),
 * no lines of its own in the summary. tests/test_bc_test_still.c runs it, and its file and row
 * are the whole of what a mode needs (docs/architecture.md). */
#include "bc.h"

typedef struct {
    long steps; /* deformation steps seen */
} still_ctx;

static cdem_status still_init(void *ctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                              cdem_error *err) {
    (void)ctx, (void)p, (void)m, (void)s, (void)err;
    return CDEM_OK;
}

static cdem_status still_apply(void *ctx, cdem_state *s, long k, double du, double dt,
                               cdem_error *err) {
    (void)s, (void)du, (void)dt, (void)err;
    if (k > 0)
        ((still_ctx *)ctx)->steps++;
    return CDEM_OK;
}

static double still_net(const void *ctx) {
    (void)ctx;
    return 0.0;
}

static void still_view(const void *ctx, FILE *out) {
    fprintf(out,
            "Boundary mode: test-still (a fixture of the tests): nothing moves; %ld "
            "deformation steps so far.\n",
            ((const still_ctx *)ctx)->steps);
}

static const cdem_bc_ops still_ops = {
    .state_size = sizeof(still_ctx), /* state_size */
    .init = still_init,              /* init: nothing to add or flag */
    .apply = still_apply,            /* apply: counts the steps, moves nothing */
    .net_displacement = still_net,   /* net_displacement: 0 */
    .view = still_view,              /* view */
    /* every other slot NULL or 0: the defaults of bc.h, which this fixture exists to run */
};

const cdem_bc_ops *const cdem_bc_test_still = &still_ops;
