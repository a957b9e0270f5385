/* bc_repose: angle-of-repose collapse. During equilibration the assembly rests between
 * both lateral walls; at the start of deformation (the begin_deformation hook, once before
 * deformation step 1) the right wall (repose_walls = right) or both lateral walls (both)
 * are removed from the state, through the solver's escape-removal path, so contact
 * histories of the remaining pairs are kept. Nothing moves afterwards: the material
 * collapses under gravity over the base, which extends beyond each removed wall by the
 * assembly's width (solver/packing/assembly.c, base_extension), so the pile spreads and comes
 * to rest on it; elements that run off the ends of the base are removed by the escape rule.
 * Net displacement is always 0; the display interval is in seconds (solver/base/model.c). */
#include "bc.h"
#include "checkpoint.h"
#include "summary_line.h"

#include <string.h>

typedef struct {
    int walls;      /* cdem_walls_choice: right or both */
    double x_mid;   /* m, walls left of this are the left wall */
    double y_base;  /* m, height of the base centres */
    double tol;     /* m, base-row tolerance in y */
    long n_walls;   /* lateral wall elements marked for removal at init */
    long n_removed; /* lateral wall elements removed by begin_deformation */
} repose_ctx;

static int is_removed_wall(const repose_ctx *c, const cdem_state *s, size_t i) {
    if (!(s->flags[i] & CDEM_FLAG_WALL) || s->y[i] <= c->y_base + c->tol)
        return 0; /* not a wall, or the base */
    return s->x[i] > c->x_mid || c->walls == CDEM_WALLS_BOTH;
}

static cdem_status repose_init(void *vctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                               cdem_error *err) {
    repose_ctx *c = vctx;
    if (p->repose_walls != CDEM_WALLS_RIGHT && p->repose_walls != CDEM_WALLS_BOTH)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "repose: boundary.repose_walls = %d: must be right or both",
                         (int)p->repose_walls);
    cdem_bc_walls w;
    CDEM_TRY(cdem_bc_find_walls(s, m, "repose", &w, err));
    c->walls = p->repose_walls;
    c->x_mid = 0.5 * m->width_m; /* not the walls' middle: the base may extend past a wall */
    c->y_base = w.y_base;
    c->tol = w.tol;
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~(uint32_t)CDEM_FLAG_MOVING;
        c->n_walls += is_removed_wall(c, s, i);
    }
    return CDEM_OK;
}

static cdem_status repose_apply(void *vctx, cdem_state *s, long k, double du, double dt,
                                cdem_error *err) {
    (void)vctx;
    (void)s;
    (void)k;
    (void)du;
    (void)dt;
    (void)err;
    return CDEM_OK; /* no boundary moves */
}

static cdem_status repose_begin(void *vctx, const cdem_state *s, unsigned char *keep,
                                size_t *n_remove, cdem_error *err) {
    (void)err;
    repose_ctx *c = vctx;
    size_t n = 0;
    for (size_t i = 0; i < s->n; i++)
        if (is_removed_wall(c, s, i)) {
            keep[i] = 0;
            n++;
        }
    c->n_removed += (long)n;
    *n_remove = n;
    return CDEM_OK;
}

static double repose_net(const void *vctx) {
    (void)vctx;
    return 0.0;
}

static void repose_view(const void *vctx, FILE *out) {
    const repose_ctx *c = vctx;
    fprintf(out,
            "Boundary mode: repose collapse, %s (%ld wall elements) removed at the start of "
            "deformation; no boundary moves afterwards; net displacement 0; display interval "
            "in seconds.\n",
            c->walls == CDEM_WALLS_BOTH ? "both lateral walls" : "the right wall", c->n_walls);
}

/* Checkpoint: only the count of removed walls evolves (the walls themselves are gone from
 * the stored state once begin_deformation has run). */
static cdem_status repose_save(const void *vctx, cdem_snapshot *snap, cdem_error *err) {
    const repose_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "x_mid", c->x_mid, err));
    return cdem_ckpt_put_i64(snap, "bc", "n_removed", c->n_removed, err);
}

static cdem_status repose_restore(void *vctx, const cdem_snapshot *snap, cdem_error *err) {
    repose_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_check_f64(snap, "bc", "x_mid", c->x_mid, err));
    int64_t n = 0;
    CDEM_TRY(cdem_ckpt_get_range(snap, "bc", "n_removed", 0, INT32_MAX, &n, err));
    c->n_removed = (long)n;
    return CDEM_OK;
}

/* What a collapse cannot run with: a load on its free surface, erosion, deposits, a physical
 * process (a test of the cover's material). */
static const char *const repose_excludes[] = {"surface.overburden_pressure", "surface.erosion",
                                              "surface.sedimentation", CDEM_EXCLUDES_PROCESSES,
                                              NULL};

/* No boundary moves: the walls go and the assembly collapses, so the display interval is in
 * seconds (cdem_model_mode). */
static void repose_derive(const cdem_params *p, cdem_model_mode *out) {
    out->moving_boundaries = 0;
    out->still = "walls removed; the assembly collapses under gravity";
    /* the base runs on past each removed wall by the assembly's width, so that the pile
     * spreads and comes to rest on it instead of draining over the base's end, where the
     * slope stood 7 deg steeper than the material (issue 34; docs/solver.md) */
    out->base_beyond_right = 1.0;
    out->base_beyond_left = p->repose_walls == CDEM_WALLS_BOTH ? 1.0 : 0.0;
}

static void repose_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    cdem_summary_line(out, "walls removed", "%s, at the end of equilibration",
                      p->repose_walls == CDEM_WALLS_BOTH ? "both walls" : "right wall");
    cdem_summary_line(out, "base", "extends %.6g m (the assembly's width) beyond %s", m->width_m,
                      p->repose_walls == CDEM_WALLS_BOTH ? "each removed wall"
                                                         : "the removed wall");
}

static const cdem_bc_ops repose_ops = {
    .state_size = sizeof(repose_ctx),  /* state_size */
    .init = repose_init,               /* init */
    .apply = repose_apply,             /* apply */
    .boundary_only = 1,                /* moves nothing */
    .net_displacement = repose_net,    /* net_displacement */
    .view = repose_view,               /* view */
    .free = NULL,                      /* free: the context owns no memory */
    .begin_deformation = repose_begin, /* removes the walls */
    .save = repose_save,               /* checkpoint: n_removed */
    .restore = repose_restore,         /* resume */
    .validate = NULL,                  /* its rules are its excludes */
    .excludes = repose_excludes,       /* overburden, erosion, sedimentation, processes */
    .inverts = 0,                      /* nothing to invert */
    .derive = repose_derive,           /* no moving boundary, interval in s */
    .describe = repose_describe,       /* which walls go */
};

const cdem_bc_ops *const cdem_bc_repose = &repose_ops;
