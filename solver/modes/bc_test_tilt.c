/* bc_test_tilt: a fixture of the tests, not a mode of the model (no parameter file can name
 * it: its row in common/modes.def is CDEM_TEST_MODE). It proves that gravity is a vector a mode
 * may set: its derive tilts gravity by TILT_START degrees from -y toward +x, and its gravity
 * hook turns it on by TILT_TURN degrees more over the deformation steps, as a margin that tilts
 * would (issue 45, item 4). Its walls never move. tests/test_bc_test_tilt.c runs it: the walls
 * carry the weight along the tilted vertical, and a run resumed from a mid-run checkpoint is
 * bit-identical to the uninterrupted one. */
#include "bc.h"
#include "checkpoint.h"

#include <math.h>

#define TILT_START 2.0 /* degrees, from the start (derive) */
#define TILT_TURN  1.0 /* degrees more at the last deformation step (the gravity hook) */

typedef struct {
    long deformation_steps; /* the run's, > 0: the turn's length */
} tilt_ctx;

static cdem_status tilt_init(void *ctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                             cdem_error *err) {
    (void)p, (void)s, (void)err;
    const long k = m->total_steps - m->equil_steps;
    ((tilt_ctx *)ctx)->deformation_steps = k > 0 ? k : 1;
    return CDEM_OK;
}

static cdem_status tilt_apply(void *ctx, cdem_state *s, long k, double du, double dt,
                              cdem_error *err) {
    (void)ctx, (void)s, (void)k, (void)du, (void)dt, (void)err;
    return CDEM_OK;
}

static double tilt_net(const void *ctx) {
    (void)ctx;
    return 0.0;
}

static void tilt_view(const void *ctx, FILE *out) {
    fprintf(out,
            "Boundary mode: test-tilt (a fixture of the tests): nothing moves; gravity tilted %g "
            "degrees toward +x, turning %g degrees more over %ld deformation steps.\n",
            TILT_START, TILT_TURN, ((const tilt_ctx *)ctx)->deformation_steps);
}

static void tilt_derive(const cdem_params *p, cdem_model_mode *out) {
    (void)p;
    out->gravity_tilt = TILT_START;
}

static void tilt_gravity(const void *ctx, long k, double g, double *gx, double *gy) {
    const tilt_ctx *c = ctx;
    const double turned = (double)(k < c->deformation_steps ? k : c->deformation_steps) /
                          (double)c->deformation_steps;
    cdem_model_gravity_vector(g, TILT_START + TILT_TURN * turned, gx, gy);
}

static cdem_status tilt_save(const void *ctx, cdem_snapshot *snap, cdem_error *err) {
    return cdem_ckpt_put_i64(snap, "bc", "deformation_steps",
                             ((const tilt_ctx *)ctx)->deformation_steps, err);
}

static cdem_status tilt_restore(void *ctx, const cdem_snapshot *snap, cdem_error *err) {
    int64_t k = 0;
    CDEM_TRY(cdem_ckpt_get_i64(snap, "bc", "deformation_steps", &k, err));
    if (k != ((tilt_ctx *)ctx)->deformation_steps)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "test-tilt: the checkpoint turns gravity over %lld deformation steps, "
                         "this run over %ld",
                         (long long)k, ((tilt_ctx *)ctx)->deformation_steps);
    return CDEM_OK;
}

static const cdem_bc_ops tilt_ops = {
    .state_size = sizeof(tilt_ctx), /* state_size */
    .init = tilt_init,              /* init: the turn's length */
    .apply = tilt_apply,            /* apply: moves nothing */
    .net_displacement = tilt_net,   /* net_displacement: 0 */
    .view = tilt_view,              /* view */
    .derive = tilt_derive,          /* gravity tilted TILT_START degrees from the start */
    .gravity = tilt_gravity,        /* and turning TILT_TURN more over the deformation */
    .save = tilt_save,              /* checkpoint: the turn's length (checked) */
    .restore = tilt_restore,        /* resume */
};

const cdem_bc_ops *const cdem_bc_test_tilt = &tilt_ops;
