/* bc_detachment: shortening over a fixed, frictional base (a detachment).
 *
 * detachment_walls = right: the right lateral wall moves left (-x) by the step's boundary
 * increment du; = both: the left wall moves right and the right wall moves left, each by
 * du (each wall at the boundary speed, as in the original program), so the model shortens
 * by 2 du per step. The base (lowest row of wall elements) never moves; its contacts with
 * elements are wall-class contacts (material.wall_*), like every wall contact. The moving
 * walls slide over the base (boundary-boundary pairs never interact). Net displacement
 * (docs/solver.md): the total shortening of the model, k du after k steps for "right" and
 * 2 k du (the sum of both walls' displacements) for "both", the value version 2.6 of the
 * original program "fixed" for this case. Increments come every display interval of
 * boundary (each wall's) displacement, as in every other mode. Units: m, s. */
#include "bc.h"
#include "checkpoint.h"
#include "summary_line.h"

#include <math.h>
#include <string.h>

typedef struct {
    int walls;              /* cdem_walls_choice: right or both */
    double x_mid;           /* m, walls left of this are the left wall */
    double net;             /* m, total shortening so far (sum over the moving walls), >= 0 */
    long n_left;            /* moving left-wall elements (0 for "right") */
    long n_right;           /* moving right-wall elements */
    double step_du, step_v; /* this step's move and speed of each wall (step_begin) */
} detach_ctx;

static cdem_status detach_init(void *vctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                               cdem_error *err) {
    detach_ctx *c = vctx;
    if (p->detachment_walls != CDEM_WALLS_RIGHT && p->detachment_walls != CDEM_WALLS_BOTH)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "detachment: boundary.detachment_walls = %d: must be right or both",
                         (int)p->detachment_walls);
    cdem_bc_walls w;
    CDEM_TRY(cdem_bc_find_walls(s, m, "detachment", &w, err));
    c->walls = p->detachment_walls;
    c->x_mid = w.x_mid;
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~(uint32_t)CDEM_FLAG_MOVING;
        if (!(s->flags[i] & CDEM_FLAG_WALL) || cdem_bc_is_base(&w, s, i))
            continue;
        if (s->x[i] > w.x_mid) {
            s->flags[i] |= CDEM_FLAG_MOVING;
            c->n_right++;
        } else if (c->walls == CDEM_WALLS_BOTH) {
            s->flags[i] |= CDEM_FLAG_MOVING;
            c->n_left++;
        }
    }
    if (c->n_right == 0)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "detachment: the assembly has no right lateral wall (wall elements "
                         "above the base right of x = %g m) to move",
                         w.x_mid);
    return CDEM_OK;
}

static cdem_status detach_step_begin(void *vctx, long k, double du, double dt, cdem_error *err) {
    (void)k;
    detach_ctx *c = vctx;
    if (!(dt > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "detachment: dt = %g s: must be > 0", dt);
    c->step_du = du;
    c->step_v = du / dt;
    /* total shortening: both walls' displacements together */
    c->net += (c->walls == CDEM_WALLS_BOTH ? 2.0 : 1.0) * du;
    return CDEM_OK;
}

static void detach_step_move(const void *vctx, cdem_state *s, long lo, long hi) {
    const detach_ctx *c = vctx;
    const double xm = c->x_mid, du = c->step_du, v = c->step_v;
    double *restrict x = s->x, *restrict vxa = s->vx, *restrict vya = s->vy;
    const uint32_t *restrict fl = s->flags;
    for (long i = lo; i < hi; i++) {
        if (fl[i] & CDEM_FLAG_MOVING) {
            /* the right wall moves left, the left wall right: both inward */
            const double sgn = x[i] > xm ? -1.0 : 1.0;
            x[i] += sgn * du;
            vxa[i] = sgn * v;
            vya[i] = 0.0;
        }
    }
}

static double detach_net(const void *vctx) {
    return ((const detach_ctx *)vctx)->net;
}

static void detach_view(const void *vctx, FILE *out) {
    const detach_ctx *c = vctx;
    if (c->walls == CDEM_WALLS_BOTH)
        fprintf(out,
                "Boundary mode: detachment, both lateral walls move inward over the fixed base "
                "at the boundary speed each (%ld left + %ld right wall elements); net "
                "displacement = total shortening (sum of both walls), an increment every "
                "display interval of each wall's displacement.\n",
                c->n_left, c->n_right);
    else
        fprintf(out,
                "Boundary mode: detachment, the right wall (%ld elements) moves left over the "
                "fixed base at the boundary speed; net displacement = the wall's "
                "displacement.\n",
                c->n_right);
}

/* Checkpoint: the shortening evolves; the walls are set by init (x_mid checked). */
static cdem_status detach_save(const void *vctx, cdem_snapshot *snap, cdem_error *err) {
    const detach_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "x_mid", c->x_mid, err));
    return cdem_ckpt_put_f64(snap, "bc", "net", c->net, err);
}

static cdem_status detach_restore(void *vctx, const cdem_snapshot *snap, cdem_error *err) {
    detach_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_check_f64(snap, "bc", "x_mid", c->x_mid, err));
    return cdem_ckpt_get_f64(snap, "bc", "net", &c->net, err);
}

/* Both walls moving inward shorten the model twice as fast. */
static void detach_derive(const cdem_params *p, cdem_model_mode *out) {
    out->moving_boundaries = p->detachment_walls == CDEM_WALLS_BOTH ? 2 : 1;
}

static void detach_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    (void)m;
    cdem_summary_line(out, "moving walls", "%s, moving inward over the base",
                      p->detachment_walls == CDEM_WALLS_BOTH ? "both walls" : "right wall");
}

static const cdem_bc_ops detach_ops = {
    .state_size = sizeof(detach_ctx), /* state_size */
    .init = detach_init,              /* init */
    .step_begin = detach_step_begin,  /* apply, split: the net displacement */
    .step_move = detach_step_move,    /* and the walls' elements */
    .boundary_only = 1,               /* moves boundary elements only */
    .net_displacement = detach_net,   /* net_displacement */
    .view = detach_view,              /* view */
    .free = NULL,                     /* free: the context owns no memory */
    .begin_deformation = NULL,        /* nothing to remove */
    .save = detach_save,              /* checkpoint: net */
    .restore = detach_restore,        /* resume */
    .validate = NULL,                 /* no rules of its own */
    .excludes = NULL,                 /* runs with every option */
    .inverts = 0,                     /* the walls only move inward */
    .derive = detach_derive,          /* one or two moving walls */
    .describe = detach_describe,      /* which walls */
};

const cdem_bc_ops *const cdem_bc_detachment = &detach_ops;
