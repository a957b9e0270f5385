/* bc_test_lift: a fixture of the tests, not a mode of the model (no parameter file can name
 * it: its row in common/modes/test_lift.h is CDEM_TEST_MODE). It proves that a mode owns its
 * parameters (issue 45, item 2): its one key, boundary.test_lift_ratio, is declared in its
 * own file common/modes/test_lift.h and gathered into the parameter table from there. On each
 * deformation step the base row (CDEM_FLAG_BASE) rises by test_lift_ratio times the step's
 * boundary increment; the lateral walls stay. tests/test_bc_test_lift.c runs it. */
#include "bc.h"
#include "checkpoint.h"

typedef struct {
    double ratio;  /* boundary.test_lift_ratio */
    double net;    /* m of boundary displacement so far */
    double lifted; /* m the base has risen so far */
} lift_ctx;

static cdem_status lift_init(void *ctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                             cdem_error *err) {
    (void)m, (void)s, (void)err;
    ((lift_ctx *)ctx)->ratio = p->test_lift_ratio;
    return CDEM_OK;
}

static cdem_status lift_apply(void *ctx, cdem_state *s, long k, double du, double dt,
                              cdem_error *err) {
    (void)err;
    lift_ctx *c = ctx;
    if (k <= 0)
        return CDEM_OK;
    const double rise = c->ratio * du;
    for (size_t i = 0; i < s->n; i++)
        if (s->flags[i] & CDEM_FLAG_BASE) {
            s->y[i] += rise;
            s->vx[i] = 0.0;
            s->vy[i] = rise / dt;
        }
    c->net += du;
    c->lifted += rise;
    return CDEM_OK;
}

static double lift_net(const void *ctx) {
    return ((const lift_ctx *)ctx)->net;
}

static void lift_view(const void *ctx, FILE *out) {
    const lift_ctx *c = ctx;
    fprintf(out,
            "Boundary mode: test-lift (a fixture of the tests): the base rises %g m per metre of "
            "boundary displacement; %g m so far.\n",
            c->ratio, c->lifted);
}

static cdem_status lift_save(const void *ctx, cdem_snapshot *snap, cdem_error *err) {
    const lift_ctx *c = ctx;
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "net", c->net, err));
    return cdem_ckpt_put_f64(snap, "bc", "lifted", c->lifted, err);
}

static cdem_status lift_restore(void *ctx, const cdem_snapshot *snap, cdem_error *err) {
    lift_ctx *c = ctx;
    CDEM_TRY(cdem_ckpt_get_f64(snap, "bc", "net", &c->net, err));
    return cdem_ckpt_get_f64(snap, "bc", "lifted", &c->lifted, err);
}

static const cdem_bc_ops lift_ops = {
    .state_size = sizeof(lift_ctx), /* state_size */
    .init = lift_init,              /* init: the ratio, from its own key */
    .apply = lift_apply,            /* apply: the base rises */
    .net_displacement = lift_net,   /* net_displacement */
    .view = lift_view,              /* view */
    .save = lift_save,              /* save: the displacement and the rise so far */
    .restore = lift_restore,        /* restore */
};

const cdem_bc_ops *const cdem_bc_test_lift = &lift_ops;
