/* bc_vertical_faults: two vertical faults through the base; the block of base between them
 * moves down (caldera) or up (piston).
 *
 * Geometry (docs/solver.md): the faults are at x1 = vertical_fault_location * width and
 * x2 = (vertical_fault_location + vertical_fault_spacing) * width; the moving block is the
 * base elements with x1 < x < x2 (flagged CDEM_FLAG_MOVING); the lateral walls and the
 * rest of the base stay fixed. Each deformation step moves the block vertically by the
 * step's boundary increment du (down for caldera, up for piston) and sets its velocity to
 * the boundary velocity. So that nothing falls into the gaps that open at the faults, a
 * vertical column of fault elements (CDEM_FLAG_FAULT, base radius, spaced one radius) is
 * laid below the base at x1 and at x2, as long as the whole displacement plus 4 radii:
 * fixed for caldera (the pit's side walls), moving with the block for piston (the block's
 * faces as it rises). Net displacement = the block's displacement along its sense (>= 0). */
#include "bc.h"
#include "checkpoint.h"
#include "summary_line.h"

#include <math.h>
#include <string.h>

typedef struct {
    int sense;               /* cdem_vertical_sense: caldera (down) or piston (up) */
    double x1, x2;           /* m, x of the first and second fault, 0 < x1 < x2 < width */
    double y_base;           /* m, height of the base centres */
    double dir_y;            /* -1 (caldera) or +1 (piston): direction of the block's motion */
    double net;              /* m, displacement of the block along dir_y so far, >= 0 */
    long n_block;            /* base elements in the moving block */
    long n_column;           /* fault-column elements added (both faults) */
    double col_length;       /* m, length of each column below the base */
    double step_uy, step_vy; /* this step's move and velocity of the block (step_begin) */
} vert_ctx;

static cdem_status vert_init(void *vctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                             cdem_error *err) {
    vert_ctx *c = vctx;
    const double loc = p->vertical_fault_location, sp = p->vertical_fault_spacing;
    if (!(loc > 0.0 && loc < 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "vertical faults: boundary.vertical_fault_location = %g: must be in "
                         "(0, 1)",
                         loc);
    if (!(sp > 0.0 && loc + sp < 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "vertical faults: boundary.vertical_fault_spacing = %g with "
                         "vertical_fault_location = %g: the spacing must be > 0 and location + "
                         "spacing < 1 (the second fault inside the base)",
                         sp, loc);
    if (p->vertical_sense != CDEM_VERT_CALDERA && p->vertical_sense != CDEM_VERT_PISTON)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "vertical faults: boundary.vertical_sense = %d: must be caldera or "
                         "piston",
                         (int)p->vertical_sense);
    cdem_bc_walls w;
    CDEM_TRY(cdem_bc_find_walls(s, m, "vertical faults", &w, err));
    c->sense = p->vertical_sense;
    c->x1 = loc * m->width_m;
    c->x2 = (loc + sp) * m->width_m;
    c->y_base = w.y_base;
    c->dir_y = p->vertical_sense == CDEM_VERT_CALDERA ? -1.0 : 1.0;
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~(uint32_t)CDEM_FLAG_MOVING;
        if ((s->flags[i] & CDEM_FLAG_WALL) && cdem_bc_is_base(&w, s, i) && s->x[i] > c->x1 &&
            s->x[i] < c->x2) {
            s->flags[i] |= CDEM_FLAG_MOVING;
            c->n_block++;
        }
    }
    if (c->n_block == 0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "vertical faults: no base element lies between the faults at x = %g m "
                         "and %g m (vertical_fault_spacing = %g): widen the spacing",
                         c->x1, c->x2, sp);
    const double rb = w.r_base;
    const uint32_t fl =
        CDEM_FLAG_FAULT | (c->sense == CDEM_VERT_PISTON ? (uint32_t)CDEM_FLAG_MOVING : 0u);
    c->col_length = m->total_displacement + 4.0 * rb;
    const long ncol = (long)ceil(c->col_length / rb);
    const double mass = p->density * M_PI * rb * rb;
    for (int f = 0; f < 2; f++) {
        const double xf = f == 0 ? c->x1 : c->x2;
        for (long k = 1; k <= ncol; k++) {
            CDEM_TRY(cdem_state_append(s, -1, xf, c->y_base - (double)k * rb, rb, mass, 0, fl, 0,
                                       NULL, err));
            c->n_column++;
        }
    }
    return CDEM_OK;
}

static cdem_status vert_step_begin(void *vctx, long k, double du, double dt, cdem_error *err) {
    (void)k;
    vert_ctx *c = vctx;
    if (!(dt > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "vertical faults: dt = %g s: must be > 0", dt);
    c->step_uy = c->dir_y * du;
    c->step_vy = c->step_uy / dt;
    c->net += du;
    return CDEM_OK;
}

static void vert_step_move(const void *vctx, cdem_state *s, long lo, long hi) {
    const vert_ctx *c = vctx;
    const double uy = c->step_uy, vy = c->step_vy;
    double *restrict y = s->y, *restrict vxa = s->vx, *restrict vya = s->vy;
    const uint32_t *restrict fl = s->flags;
    for (long i = lo; i < hi; i++) {
        if (fl[i] & CDEM_FLAG_MOVING) {
            y[i] += uy;
            vxa[i] = 0.0;
            vya[i] = vy;
        }
    }
}

static double vert_net(const void *vctx) {
    return ((const vert_ctx *)vctx)->net;
}

static void vert_view(const void *vctx, FILE *out) {
    const vert_ctx *c = vctx;
    fprintf(out,
            "Boundary mode: two vertical faults at x = %.1f m and x = %.1f m; the base block "
            "between them (%ld elements) moves %s (%s); %ld %s fault-column elements below "
            "the base along the two faults, each column %.1f m long.\n",
            c->x1, c->x2, c->n_block, c->sense == CDEM_VERT_CALDERA ? "down" : "up",
            c->sense == CDEM_VERT_CALDERA ? "caldera" : "piston", c->n_column,
            c->sense == CDEM_VERT_CALDERA ? "fixed" : "moving", c->col_length);
}

/* Checkpoint: the block's displacement evolves; the faults are set by init (x1, x2 checked). */
static cdem_status vert_save(const void *vctx, cdem_snapshot *snap, cdem_error *err) {
    const vert_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "x1", c->x1, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "x2", c->x2, err));
    return cdem_ckpt_put_f64(snap, "bc", "net", c->net, err);
}

static cdem_status vert_restore(void *vctx, const cdem_snapshot *snap, cdem_error *err) {
    vert_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_check_f64(snap, "bc", "x1", c->x1, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, "bc", "x2", c->x2, err));
    return cdem_ckpt_get_f64(snap, "bc", "net", &c->net, err);
}

/* The second fault must lie inside the base. */
static void vert_validate(const cdem_params *p, cdem_rule_log *log) {
    if (p->vertical_fault_location + p->vertical_fault_spacing < 1.0)
        return;
    char v1[64], v2[64];
    cdem_params_format_number(p->vertical_fault_location, v1, sizeof v1);
    cdem_params_format_number(p->vertical_fault_spacing, v2, sizeof v2);
    cdem_rule_add(log,
                  "mode = vertical-faults: vertical_fault_location + vertical_fault_spacing = %s "
                  "+ %s must be < 1 (the second fault must lie inside the base): reduce one of "
                  "them",
                  v1, v2);
}

static void vert_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    const double first = p->vertical_fault_location;
    const double second = p->vertical_fault_location + p->vertical_fault_spacing;
    cdem_summary_line(out, "sense", "%s",
                      p->vertical_sense == CDEM_VERT_PISTON ? "piston (block up, compression)"
                                                            : "caldera (block down, extension)");
    cdem_summary_line(out, "first fault", "%g of the base = %.6g m from the left end", first,
                      first * m->width_m);
    cdem_summary_line(out, "second fault", "%g of the base = %.6g m from the left end", second,
                      second * m->width_m);
    cdem_summary_line(out, "block width", "%.6g m", p->vertical_fault_spacing * m->width_m);
}

static const cdem_bc_ops vert_ops = {
    .state_size = sizeof(vert_ctx), /* state_size */
    .init = vert_init,              /* init */
    .step_begin = vert_step_begin,  /* apply, split: the net displacement */
    .step_move = vert_step_move,    /* and the block's elements */
    .boundary_only = 1,             /* moves boundary elements only */
    .net_displacement = vert_net,   /* net_displacement */
    .view = vert_view,              /* view */
    .free = NULL,                   /* free: the context owns no memory */
    .begin_deformation = NULL,      /* nothing to remove */
    .save = vert_save,              /* checkpoint: net */
    .restore = vert_restore,        /* resume */
    .validate = vert_validate,      /* the second fault inside the base */
    .excludes = NULL,               /* runs with every option */
    .inverts = 0,                   /* caldera or piston, never both */
    .derive = NULL,                 /* the defaults: gravity, one moving block */
    .describe = vert_describe,      /* sense, faults, block */
};

const cdem_bc_ops *const cdem_bc_vertical_faults = &vert_ops;
