/* bc_planar_fault: a planar normal or reverse fault through the base (template for modes).
 *
 * Geometry (docs/solver.md has the sketch): the base (the lowest row of wall elements) is
 * split at x_f = fault_location * width; the fault plane passes through (x_f, y_b), y_b the
 * height of the base centres, and dips toward +x at fault_dip. The hanging-wall block (the
 * base right of x_f and the right lateral wall) moves parallel to the plane: down-dip
 * (cos d, -sin d) for normal, up-dip for reverse; inversion reverses the sense after
 * inversion_percent of the deformation steps. So that no element falls through the gap
 * that opens, two ramps of fault elements (CDEM_FLAG_FAULT, radius of the base elements,
 * spaced by one radius) are laid along the plane below the base, from x_f down-dip for the
 * whole displacement: a fixed footwall ramp (present when the motion has a normal part) and
 * a hanging-wall ramp moving with the block (present when it has a reverse part), which
 * becomes the exposed fault face as the block rises. Ramps and walls never interact with
 * each other (boundary-boundary pairs are skipped).
 * One of several boundary actors (bc.h): its block's elements carry its model's moving flag,
 * and its adopt hook adds the other actors' fault elements that lie in its hanging wall (on
 * the hanging-wall side of its plane up to the top of the assembly, right of the plane's top
 * above it), so that a later fault's ramp (or a listric fault's curve) rides with this block,
 * and this block's ramps with a later fault's hanging wall. With several actors it adds its
 * velocity to the others' (bc.h): a block in the hanging walls of two faults acting at once
 * moves by both. */
#include "bc.h"
#include "checkpoint.h"
#include "summary_line.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double dip_deg;      /* fault dip, degrees, (0, 90] */
    int sense;           /* initial cdem_fault_sense */
    int inversion;       /* 1: the sense reverses at k_inversion */
    long k_inversion;    /* last deformation step of the initial sense */
    double x_fault;      /* m, x where the plane meets the base */
    double y_base;       /* m, height of the base centres */
    double dir_x, dir_y; /* unit direction of the initial sense of motion */
    double net;          /* m, net displacement along dir (initial sense positive) */
    double gross;        /* m, total path length of the block */
    long n_moving;       /* elements flagged CDEM_FLAG_MOVING */
    long n_ramp_fixed;   /* fixed footwall ramp elements added */
    long n_ramp_moving;  /* moving hanging-wall ramp elements added */
    double ramp_length;  /* m, length of each ramp along the plane */
    double step_ux, step_uy, step_vx, step_vy; /* this step's move and velocity (step_begin) */
    uint32_t moving;                           /* the flag of its block (cdem_bc_moving_flag) */
    int32_t ramp_id_lo, ramp_id_hi;            /* ids of its own ramps: [lo, hi) */
    int composed;                              /* 1: one of several actors: adds velocities */
    double x_top, y_top; /* m, the plane at the top of the assembly (adopt: vertical above) */
} planar_ctx;

static cdem_status planar_init(void *vctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                               cdem_error *err) {
    planar_ctx *c = vctx;
    if (!(p->fault_dip > 0.0 && p->fault_dip <= 90.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "planar fault: boundary.fault_dip = %g degrees: must be in (0, 90]",
                         p->fault_dip);
    if (!(p->fault_location > 0.0 && p->fault_location < 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "planar fault: boundary.fault_location = %g: must be in (0, 1)",
                         p->fault_location);
    if (p->inversion && !(p->inversion_percent >= 0.0 && p->inversion_percent <= 100.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "planar fault: boundary.inversion_percent = %g: must be in 0-100",
                         p->inversion_percent);
    /* the base: the lowest row of wall elements */
    double ymin = INFINITY, rbase = INFINITY;
    for (size_t i = 0; i < s->n; i++)
        if (s->flags[i] & CDEM_FLAG_WALL)
            ymin = fmin(ymin, s->y[i]);
    if (!isfinite(ymin))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "planar fault: the assembly has no wall elements (CDEM_FLAG_WALL), so "
                         "there is no base to split");
    const double tol = 0.5 * m->radius[0];
    double xmax_wall = -INFINITY, xmin_wall = INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_WALL))
            continue;
        xmax_wall = fmax(xmax_wall, s->x[i]);
        xmin_wall = fmin(xmin_wall, s->x[i]);
        if (s->y[i] <= ymin + tol)
            rbase = fmin(rbase, s->radius[i]);
    }
    c->dip_deg = p->fault_dip;
    c->sense = p->fault_sense;
    c->inversion = p->inversion ? 1 : 0;
    c->k_inversion = cdem_model_inversion_step(p, m);
    c->x_fault = p->fault_location * m->width_m;
    c->y_base = ymin;
    const double d = p->fault_dip * M_PI / 180.0;
    const double sgn = p->fault_sense == CDEM_SENSE_NORMAL ? 1.0 : -1.0;
    c->dir_x = sgn * cos(d);
    c->dir_y = -sgn * sin(d);
    c->moving = cdem_bc_moving_flag(m);
    c->composed = m->composed;
    double top = ymin;
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY))
            top = fmax(top, s->y[i] + s->radius[i]);
    c->y_top = top;
    c->x_top = c->x_fault - (top - ymin) * cos(d) / sin(d);
    /* the hanging-wall block: base right of x_f plus the right lateral wall */
    const double xmid = 0.5 * (xmin_wall + xmax_wall);
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~c->moving;
        if (!(s->flags[i] & CDEM_FLAG_WALL))
            continue;
        const int is_base = s->y[i] <= ymin + tol;
        if ((is_base && s->x[i] > c->x_fault) || (!is_base && s->x[i] > xmid)) {
            s->flags[i] |= c->moving;
            c->n_moving++;
        }
    }
    c->ramp_id_lo = s->next_id;
    /* ramps along the plane below the base */
    const int has_normal = p->fault_sense == CDEM_SENSE_NORMAL || c->inversion;
    const int has_reverse = p->fault_sense == CDEM_SENSE_REVERSE || c->inversion;
    c->ramp_length = m->total_displacement + 4.0 * rbase;
    const long nramp = (long)ceil(c->ramp_length / rbase);
    for (int which = 0; which < 2; which++) {
        if ((which == 0 && !has_normal) || (which == 1 && !has_reverse))
            continue;
        const uint32_t fl = CDEM_FLAG_FAULT | (which == 1 ? c->moving : 0u);
        for (long k = 1; k <= nramp; k++) {
            const double sd = (double)k * rbase;
            const double mass = p->density * M_PI * rbase * rbase;
            CDEM_TRY(cdem_state_append(s, -1, c->x_fault + sd * cos(d), c->y_base - sd * sin(d),
                                       rbase, mass, 0, fl, 0, NULL, err));
            if (which == 0)
                c->n_ramp_fixed++;
            else {
                c->n_ramp_moving++;
                c->n_moving++;
            }
        }
    }
    c->ramp_id_hi = s->next_id;
    return CDEM_OK;
}

/* The other actors' fault elements on the hanging-wall side of the plane join the block: the
 * plane through (x_f, y_b) dipping toward +x leaves the hanging wall where
 * (x - x_f) sin d - (y_b - y) cos d > 0; above the top of the assembly the side is x > x_top
 * (vertical), so that a listric fault's elements above it stay with their own block. */
static void planar_adopt(void *vctx, cdem_state *s) {
    planar_ctx *c = vctx;
    const double d = c->dip_deg * M_PI / 180.0, sd = sin(d), cd = cos(d);
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_FAULT) || (s->flags[i] & c->moving) ||
            (s->id[i] >= c->ramp_id_lo && s->id[i] < c->ramp_id_hi))
            continue;
        const int hanging = s->y[i] > c->y_top
                                ? s->x[i] > c->x_top
                                : (s->x[i] - c->x_fault) * sd - (c->y_base - s->y[i]) * cd > 0.0;
        if (hanging) {
            s->flags[i] |= c->moving;
            c->n_moving++;
        }
    }
}

static cdem_status planar_step_begin(void *vctx, long k, double du, double dt, cdem_error *err) {
    planar_ctx *c = vctx;
    if (!(dt > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "planar fault: dt = %g s: must be > 0", dt);
    const double sgn = (k <= c->k_inversion) ? 1.0 : -1.0;
    c->step_ux = sgn * du * c->dir_x;
    c->step_uy = sgn * du * c->dir_y;
    c->step_vx = c->step_ux / dt;
    c->step_vy = c->step_uy / dt;
    c->net += sgn * du;
    c->gross += du;
    return CDEM_OK;
}

/* step_move of one of several actors: the velocity is added to the others' (bc.h). */
static void planar_step_move_composed(const planar_ctx *c, cdem_state *s, long lo, long hi) {
    for (long i = lo; i < hi; i++)
        if (s->flags[i] & c->moving) {
            s->x[i] += c->step_ux;
            s->y[i] += c->step_uy;
            s->vx[i] += c->step_vx;
            s->vy[i] += c->step_vy;
        }
}

static void planar_step_move(const void *vctx, cdem_state *s, long lo, long hi) {
    const planar_ctx *c = vctx;
    if (c->composed) {
        planar_step_move_composed(c, s, lo, hi);
        return;
    }
    const double ux = c->step_ux, uy = c->step_uy, vx = c->step_vx, vy = c->step_vy;
    double *restrict x = s->x, *restrict y = s->y, *restrict vxa = s->vx, *restrict vya = s->vy;
    const uint32_t *restrict fl = s->flags;
    const uint32_t moving = c->moving;
    for (long i = lo; i < hi; i++) {
        if (fl[i] & moving) {
            x[i] += ux;
            y[i] += uy;
            vxa[i] = vx;
            vya[i] = vy;
        }
    }
}

static double planar_net(const void *vctx) {
    return ((const planar_ctx *)vctx)->net;
}

static void planar_view(const void *vctx, FILE *out) {
    const planar_ctx *c = vctx;
    fprintf(out,
            "Boundary mode: planar %s fault, dip %.1f deg toward +x, through the base at "
            "x = %.1f m (y = %.1f m); hanging-wall block = base right of the fault + right "
            "wall + %ld moving fault-ramp elements (%ld moving in all); fixed footwall ramp "
            "of %ld elements; ramps %.1f m long along the fault.",
            c->sense == CDEM_SENSE_NORMAL ? "normal" : "reverse", c->dip_deg, c->x_fault, c->y_base,
            c->n_ramp_moving, c->n_moving, c->n_ramp_fixed, c->ramp_length);
    if (c->inversion)
        fprintf(out, " Inversion after deformation step %ld.", c->k_inversion);
    fprintf(out, "\n");
}

/* Checkpoint: net and gross displacement evolve; the geometry is set by init on the same
 * assembly (x_fault and the direction are checked). */
static cdem_status planar_save(const void *vctx, cdem_snapshot *snap, cdem_error *err) {
    const planar_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "x_fault", c->x_fault, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "dir_x", c->dir_x, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "dir_y", c->dir_y, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "net", c->net, err));
    return cdem_ckpt_put_f64(snap, "bc", "gross", c->gross, err);
}

static cdem_status planar_restore(void *vctx, const cdem_snapshot *snap, cdem_error *err) {
    planar_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_check_f64(snap, "bc", "x_fault", c->x_fault, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, "bc", "dir_x", c->dir_x, err));
    CDEM_TRY(cdem_ckpt_check_f64(snap, "bc", "dir_y", c->dir_y, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, "bc", "net", &c->net, err));
    return cdem_ckpt_get_f64(snap, "bc", "gross", &c->gross, err);
}

/* The summary's lines: the fault, its dip, the inversion. */
static void planar_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    cdem_bc_describe_fault(p, m, out);
    cdem_summary_line(out, "fault dip", "%g degrees", p->fault_dip);
    cdem_bc_describe_inversion(p, m, out);
}

/* The trace: the plane from (x_f, 0) up-dip to the top of the assembly. */
static cdem_status planar_trace(const cdem_params *p, const cdem_model *m, double height,
                                cdem_fault_polyline *out, cdem_error *err) {
    memset(out, 0, sizeof *out);
    out->x = malloc(2 * sizeof *out->x);
    out->y = malloc(2 * sizeof *out->y);
    if (!out->x || !out->y) {
        cdem_fault_file_free(out);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "planar fault: out of memory for its trace");
    }
    const double d = p->fault_dip * M_PI / 180.0;
    out->n = 2;
    out->x[0] = p->fault_location * m->width_m;
    out->y[0] = 0.0;
    out->x[1] = out->x[0] - height * cos(d) / sin(d);
    out->y[1] = height;
    return CDEM_OK;
}

static const cdem_bc_ops planar_ops = {
    .state_size = sizeof(planar_ctx), /* state_size */
    .init = planar_init,              /* init */
    .step_begin = planar_step_begin,  /* apply, split: the sense, the net displacement */
    .step_move = planar_step_move,    /* and the block's elements */
    .boundary_only = 1,               /* moves boundary elements only */
    .net_displacement = planar_net,   /* net_displacement */
    .view = planar_view,              /* view */
    .free = NULL,                     /* free: the context owns no memory */
    .save = planar_save,              /* checkpoint: net, gross */
    .restore = planar_restore,        /* resume */
    .validate = NULL,                 /* no rules of its own (the table's ranges suffice) */
    .excludes = NULL,                 /* runs with every option */
    .inverts = 1,                     /* boundary.inversion reverses the block's motion */
    .derive = NULL,                   /* the defaults: gravity, one moving block */
    .describe = planar_describe,      /* sense, location, dip, inversion */
    .composes = 1,                    /* one of several actors: its own moving flag */
    .adopt = planar_adopt,            /* the other actors' ramps in its hanging wall */
    .trace = planar_trace,            /* its plane, for the checks of several faults */
};

const cdem_bc_ops *const cdem_bc_planar_fault = &planar_ops;
