/* bc_registry: the table from cdem_mode to the ops of its implementation. Adding a mode is
 * one new bc_<name>.c plus one row here; modes without a row fail with a clear message. */
#include "bc.h"

#include "checkpoint.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    cdem_mode mode;                /* the parameter value */
    const char *name;              /* its word, for messages when unimplemented */
    const cdem_bc_ops *const *ops; /* implementation, or NULL while not written */
} bc_row;

static const bc_row registry[] = {
    {CDEM_MODE_PLANAR_FAULT, "planar-fault", &cdem_bc_planar_fault},
    {CDEM_MODE_LISTRIC_FAULT, "listric-fault", &cdem_bc_listric_fault},
    {CDEM_MODE_IRREGULAR_FAULT, "irregular-fault", &cdem_bc_irregular_fault},
    {CDEM_MODE_VERTICAL_FAULTS, "vertical-faults", &cdem_bc_vertical_faults},
    {CDEM_MODE_DETACHMENT, "detachment", &cdem_bc_detachment},
    {CDEM_MODE_REPOSE, "repose", &cdem_bc_repose},
    {CDEM_MODE_BIAXIAL, "biaxial", &cdem_bc_biaxial},
};

const char *cdem_bc_implemented(void) {
    return "planar-fault, listric-fault, irregular-fault, vertical-faults, detachment, repose, "
           "biaxial";
}

cdem_status cdem_bc_find(cdem_mode mode, const cdem_bc_ops **ops, cdem_error *err) {
    for (size_t i = 0; i < sizeof registry / sizeof registry[0]; i++) {
        if (registry[i].mode != mode)
            continue;
        if (!registry[i].ops)
            return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                             "boundary.mode = %s is not implemented in this build; implemented "
                             "modes: %s",
                             registry[i].name, cdem_bc_implemented());
        *ops = *registry[i].ops;
        return CDEM_OK;
    }
    return CDEM_FAIL(err, CDEM_ERR_RANGE, "boundary.mode = %d: unknown mode; implemented modes: %s",
                     (int)mode, cdem_bc_implemented());
}

cdem_status cdem_bc_init(cdem_bc *bc, const cdem_params *p, const cdem_model *m, cdem_state *s,
                         cdem_error *err) {
    memset(bc, 0, sizeof *bc);
    const cdem_bc_ops *ops = NULL;
    CDEM_TRY(cdem_bc_find(p->mode, &ops, err));
    bc->ctx = calloc(1, ops->state_size);
    if (!bc->ctx)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the %s boundary mode", ops->name);
    bc->ops = ops;
    bc->lateral_pressure = ops->confined ? p->confining_pressure : 0.0;
    cdem_status st = ops->init(bc->ctx, p, m, s, err);
    if (st != CDEM_OK) {
        cdem_bc_free(bc);
        return st;
    }
    return CDEM_OK;
}

cdem_status cdem_bc_apply(cdem_bc *bc, cdem_state *s, long k, double du, double dt,
                          cdem_error *err) {
    if (!bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_bc_apply: boundary mode not initialised");
    if (k <= 0 && !bc->ops->moves_in_equilibration)
        return CDEM_OK;
    if (bc->ops->step_begin && bc->ops->step_move) {
        CDEM_TRY(bc->ops->step_begin(bc->ctx, k <= 0 ? 0 : k, du, dt, err));
        bc->ops->step_move(bc->ctx, s, 0, (long)s->n);
        return CDEM_OK;
    }
    if (!bc->ops->apply)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_apply: mode %s has neither apply nor step_begin and step_move",
                         bc->ops->name);
    return bc->ops->apply(bc->ctx, s, k <= 0 ? 0 : k, du, dt, err);
}

cdem_bc_move_fn cdem_bc_step_move_of(const cdem_bc *bc, long k) {
    if (!bc || !bc->ops || !bc->ops->step_begin || !bc->ops->boundary_only)
        return NULL;
    if (k <= 0 && !bc->ops->moves_in_equilibration)
        return NULL; /* nothing moves in this step */
    return bc->ops->step_move;
}

cdem_status cdem_bc_step_begin(cdem_bc *bc, long k, double du, double dt, cdem_error *err) {
    if (!bc || !bc->ops || !bc->ops->step_begin)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_bc_step_begin: the mode has no step_begin");
    return bc->ops->step_begin(bc->ctx, k <= 0 ? 0 : k, du, dt, err);
}

int cdem_bc_apply_is_boundary_only(const cdem_bc *bc, long k) {
    if (!bc || !bc->ops)
        return 0;
    return bc->ops->boundary_only || (k <= 0 && !bc->ops->moves_in_equilibration);
}

int cdem_bc_moves_in_equilibration(const cdem_bc *bc) {
    return bc && bc->ops && bc->ops->moves_in_equilibration;
}

double cdem_bc_net_displacement(const cdem_bc *bc) {
    return (bc && bc->ops) ? bc->ops->net_displacement(bc->ctx) : 0.0;
}

cdem_status cdem_bc_begin_deformation(cdem_bc *bc, const cdem_state *s, unsigned char *keep,
                                      size_t *n_remove, cdem_error *err) {
    *n_remove = 0;
    if (!bc || !bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_begin_deformation: boundary mode not initialised");
    if (!bc->ops->begin_deformation)
        return CDEM_OK;
    return bc->ops->begin_deformation(bc->ctx, s, keep, n_remove, err);
}

void cdem_bc_view(const cdem_bc *bc, FILE *out) {
    if (bc && bc->ops)
        bc->ops->view(bc->ctx, out);
}

double cdem_bc_lateral_pressure(const cdem_bc *bc) {
    return (bc && bc->ops) ? bc->lateral_pressure : 0.0;
}

void cdem_bc_measure(cdem_bc *bc, const cdem_state *s, long step, int sample, double *axial_strain,
                     double *differential_stress) {
    *axial_strain = 0.0;
    *differential_stress = 0.0;
    if (bc && bc->ops && bc->ops->measure)
        bc->ops->measure(bc->ctx, s, step, sample, axial_strain, differential_stress);
}

void cdem_bc_free(cdem_bc *bc) {
    if (!bc)
        return;
    if (bc->ops && bc->ops->free && bc->ctx)
        bc->ops->free(bc->ctx);
    free(bc->ctx);
    bc->ctx = NULL;
    bc->ops = NULL;
    bc->lateral_pressure = 0.0;
}

cdem_status cdem_bc_find_walls(const cdem_state *s, const cdem_model *m, const char *mode,
                               cdem_bc_walls *w, cdem_error *err) {
    memset(w, 0, sizeof *w);
    double ymin = INFINITY, xmin = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < s->n; i++)
        if (s->flags[i] & CDEM_FLAG_WALL) {
            ymin = fmin(ymin, s->y[i]);
            xmin = fmin(xmin, s->x[i]);
            xmax = fmax(xmax, s->x[i]);
        }
    if (!isfinite(ymin))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: the assembly has no wall elements (CDEM_FLAG_WALL), so there is "
                         "no base",
                         mode);
    w->y_base = ymin;
    w->tol = 0.5 * m->radius[0];
    w->x_min = xmin;
    w->x_max = xmax;
    w->x_mid = 0.5 * (xmin + xmax);
    double rb = INFINITY;
    for (size_t i = 0; i < s->n; i++)
        if ((s->flags[i] & CDEM_FLAG_WALL) && cdem_bc_is_base(w, s, i))
            rb = fmin(rb, s->radius[i]);
    if (!(rb > 0.0 && isfinite(rb)))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "%s: base element radius = %g m: must be > 0", mode,
                         rb);
    w->r_base = rb;
    return CDEM_OK;
}

cdem_status cdem_bc_snapshot_put(const cdem_bc *bc, cdem_snapshot *snap, cdem_error *err) {
    if (!bc || !bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_snapshot_put: boundary mode not initialised");
    if (!bc->ops->save)
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "boundary mode %s cannot write checkpoints in this build (set "
                         "output.checkpoint_interval = 0)",
                         bc->ops->name);
    CDEM_TRY(cdem_ckpt_put_text(snap, "bc", "mode", bc->ops->name, err));
    return bc->ops->save(bc->ctx, snap, err);
}

cdem_status cdem_bc_snapshot_get(cdem_bc *bc, const cdem_snapshot *snap, cdem_error *err) {
    if (!bc || !bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_snapshot_get: boundary mode not initialised");
    if (!bc->ops->restore)
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "boundary mode %s cannot resume from a checkpoint in this build",
                         bc->ops->name);
    CDEM_TRY(cdem_ckpt_check_text(snap, "bc", "mode", bc->ops->name, "boundary mode", err));
    return bc->ops->restore(bc->ctx, snap, err);
}
