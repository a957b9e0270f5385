/* bc_detachment: shortening or extension over a fixed, frictional base (a detachment).
 *
 * detachment_walls = right: the right lateral wall moves by the step's boundary increment du;
 * = both: the left and the right wall each move by du (each wall at the boundary speed, as
 * in the original program), so the model's length changes by 2 du per step.
 * detachment_sense = shortening (the original's mode): the walls move inward, the right one
 * left (-x); = extension (beyond the original): outward, the right one right (+x): the
 * thin-skinned extension of a cover spreading over its detachment toward the retreating
 * wall (over a viscous substrate, the set-up of Vendeville and Jackson's 1992 analogue models;
 * issue 37, docs/solver.md section 4). With extension the base runs on past each moving wall by one
 * assembly width (derive: base_beyond_*), so the spreading material stays on it; a wall
 * that moves farther than that leaves the base's end, where the escape rule removes what
 * falls off (docs/solver.md).
 * The base (lowest row of wall elements) never moves; its contacts with elements are
 * wall-class contacts (material.wall_*), like every wall contact. The moving walls slide
 * over the base (boundary-boundary pairs never interact). Net displacement
 * (docs/solver.md): the total shortening (or extension) of the model, k du after k steps
 * for "right" and 2 k du (the sum of both walls' displacements) for "both", the value
 * version 2.6 of the original program "fixed" for this case. Increments come every display
 * interval of boundary (each wall's) displacement, as in every other mode. Units: m, s. */
#include "bc.h"
#include "checkpoint.h"
#include "summary_line.h"

#include <math.h>
#include <string.h>

typedef struct {
    int walls;      /* cdem_walls_choice: right or both */
    double outward; /* +1: extension (walls outward), -1: shortening (inward) */
    double x_mid;   /* m, walls left of this are the left wall */
    double net;     /* m, total shortening or extension so far (sum over the moving walls), >= 0 */
    long n_left;    /* moving left-wall elements (0 for "right") */
    long n_right;   /* moving right-wall elements */
    double step_du, step_v; /* this step's move and speed of each wall (step_begin) */
} detach_ctx;

static cdem_status detach_init(void *vctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                               cdem_error *err) {
    detach_ctx *c = vctx;
    if (p->detachment_walls != CDEM_WALLS_RIGHT && p->detachment_walls != CDEM_WALLS_BOTH)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "detachment: boundary.detachment_walls = %d: must be right or both",
                         (int)p->detachment_walls);
    if (p->detachment_sense != CDEM_DETACH_SHORTENING &&
        p->detachment_sense != CDEM_DETACH_EXTENSION)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "detachment: boundary.detachment_sense = %d: must be shortening or "
                         "extension",
                         (int)p->detachment_sense);
    cdem_bc_walls w;
    CDEM_TRY(cdem_bc_find_walls(s, m, "detachment", &w, err));
    c->walls = p->detachment_walls;
    c->outward = p->detachment_sense == CDEM_DETACH_EXTENSION ? 1.0 : -1.0;
    /* with extension the base runs on past a moving wall (derive), so the walls' middle is
     * not the middle of every wall element: the assembly's middle is */
    c->x_mid = c->outward > 0.0 ? 0.5 * m->width_m : w.x_mid;
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~(uint32_t)CDEM_FLAG_MOVING;
        if (!(s->flags[i] & CDEM_FLAG_WALL) || cdem_bc_is_base(&w, s, i))
            continue;
        if (s->x[i] > c->x_mid) {
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
                         c->x_mid);
    return CDEM_OK;
}

static cdem_status detach_step_begin(void *vctx, long k, double du, double dt, cdem_error *err) {
    (void)k;
    detach_ctx *c = vctx;
    if (!(dt > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "detachment: dt = %g s: must be > 0", dt);
    c->step_du = du;
    c->step_v = du / dt;
    /* total shortening or extension: both walls' displacements together */
    c->net += (c->walls == CDEM_WALLS_BOTH ? 2.0 : 1.0) * du;
    return CDEM_OK;
}

static void detach_step_move(const void *vctx, cdem_state *s, long lo, long hi) {
    const detach_ctx *c = vctx;
    const double xm = c->x_mid, du = c->step_du, v = c->step_v, out = c->outward;
    double *restrict x = s->x, *restrict vxa = s->vx, *restrict vya = s->vy;
    const uint32_t *restrict fl = s->flags;
    for (long i = lo; i < hi; i++) {
        if (fl[i] & CDEM_FLAG_MOVING) {
            /* shortening: the right wall moves left, the left wall right (both inward);
             * extension: both outward */
            const double sgn = x[i] > xm ? out : -out;
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
    const int ext = c->outward > 0.0;
    if (c->walls == CDEM_WALLS_BOTH)
        fprintf(out,
                "Boundary mode: detachment, both lateral walls move %s over the fixed base "
                "at the boundary speed each (%ld left + %ld right wall elements); net "
                "displacement = total %s (sum of both walls), an increment every "
                "display interval of each wall's displacement.\n",
                ext ? "outward" : "inward", c->n_left, c->n_right,
                ext ? "extension" : "shortening");
    else
        fprintf(out,
                "Boundary mode: detachment, the right wall (%ld elements) moves %s over the "
                "fixed base at the boundary speed (%s); net displacement = the wall's "
                "displacement.\n",
                c->n_right, ext ? "right" : "left", ext ? "extension" : "shortening");
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

/* Both walls moving shorten (or extend) the model twice as fast. With extension the base
 * runs on past each moving wall by one assembly width, for the material that follows it. */
static void detach_derive(const cdem_params *p, cdem_model_mode *out) {
    const int both = p->detachment_walls == CDEM_WALLS_BOTH;
    out->moving_boundaries = both ? 2 : 1;
    if (p->detachment_sense == CDEM_DETACH_EXTENSION) {
        out->base_beyond_right = 1.0;
        out->base_beyond_left = both ? 1.0 : 0.0;
    }
}

static void detach_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    (void)m;
    cdem_summary_line(out, "moving walls", "%s, moving %s over the base (%s)",
                      p->detachment_walls == CDEM_WALLS_BOTH ? "both walls" : "right wall",
                      p->detachment_sense == CDEM_DETACH_EXTENSION ? "outward" : "inward",
                      p->detachment_sense == CDEM_DETACH_EXTENSION ? "extension" : "shortening");
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
    .inverts = 0,                     /* the walls keep their sense */
    .derive = detach_derive,          /* one or two moving walls */
    .describe = detach_describe,      /* which walls */
};

const cdem_bc_ops *const cdem_bc_detachment = &detach_ops;
