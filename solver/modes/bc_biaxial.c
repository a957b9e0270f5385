/* bc_biaxial: the uni/biaxial test of a 10 x 5 unit sample, gravity off (solver/base/model.c).
 * Init: the base row is the bottom platen; a top platen of wall elements (base radius r,
 * spaced r) is added one radius above the highest free element; both platens extend 25% of
 * the base length beyond each end and are CDEM_FLAG_MOVING. Platen contacts are wall-class
 * contacts (material.wall_*), as in every mode. Equilibration: the lateral walls
 * hold the sample while the solver ramps the confining pressure p on the free edges from 0 at
 * mid-equilibration to full at its end; the platens are servo-controlled (apply, k = 0) to
 * carry the same ramped pressure, so the sample starts isotropic. Deformation: the lateral
 * walls are removed; each platen moves inward at half the boundary speed (closure per step =
 * du = net displacement). Measurements (each time-series sample): axial strain = closure / H0
 * (H0 = gap between the platens' inner faces at the start of deformation); differential
 * stress = F / L - p x ramp, F = mean |contact force y| of the two platens, L = span of the
 * free elements, both averaged over the samples of the last 5 increments (v3.1), minus the
 * value at the end of equilibration (v2.6). The material, its damping included, is the
 * same as in every other mode. Single-threaded; units m, N, N/m. */
#include "bc.h"
#include "checkpoint.h"
#include "summary_line.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double pressure; /* N/m, confining pressure (boundary.confining_pressure), >= 0 */
    long equil;      /* steps of equilibration (ramp and correction reference) */
    double y_mid;    /* m, platen elements above this are the top platen */
    double y_bottom; /* m, bottom platen centre height (moves up by du/2 per step) */
    double y_top;    /* m, top platen centre height (moves down by du/2 per step) */
    double r_bottom; /* m, bottom platen radius (the smallest base radius) */
    double r_top;    /* m, top platen radius, = r_bottom */
    double h0;       /* m, gap between the platens' inner faces before deformation, > 0 */
    double closure;  /* m, platen closure so far, >= 0 */
    long n_top;      /* top platen elements added */
    long n_extend;   /* bottom platen elements added beyond the base ends */
    long n_walls;    /* lateral wall elements (removed at the start of deformation) */
    size_t window;   /* samples averaged (5 increments' worth), >= 1 */
    double *ring_f;  /* window entries: mean |platen force y|, N */
    double *ring_l;  /* window entries: free-element span, m */
    size_t n_ring;   /* entries filled, <= window */
    size_t head;     /* next ring slot to write */
    int have_ref;    /* 1 once the end-of-equilibration reference is taken */
    double ref;      /* N/m, differential stress at the end of equilibration */
    double last;     /* N/m, uncorrected differential stress of the last sample */
    double kn;       /* N/m, contact normal stiffness (servo gain scale), > 0 */
    long eq_step;    /* equilibration steps done (servo ramp), 0..equil */
    double servo;    /* N/m, last servo target axial stress p x ramp, >= 0 */
} biaxial_ctx;

/* Servo gain: fraction of the force error closed per step through the platen contacts. */
#define BIAXIAL_SERVO_GAIN 0.5
/* Servo speed limit: platen travel per step at most this many boundary increments du. */
#define BIAXIAL_SERVO_SPEED 10.0

static int is_platen(uint32_t f) {
    return (f & CDEM_FLAG_WALL) && (f & CDEM_FLAG_MOVING);
}

static cdem_status biaxial_init(void *vctx, const cdem_params *p, const cdem_model *m,
                                cdem_state *s, cdem_error *err) {
    biaxial_ctx *c = vctx;
    if (!(p->confining_pressure >= 0.0) || !isfinite(p->confining_pressure))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "biaxial: boundary.confining_pressure = %g N/m: must be a finite "
                         "number >= 0",
                         p->confining_pressure);
    if (p->overburden_pressure > 0.0)
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "biaxial: surface.overburden_pressure = %g N/m: the biaxial test takes "
                         "no overburden; set it to 0",
                         p->overburden_pressure);
    cdem_bc_walls w;
    CDEM_TRY(cdem_bc_find_walls(s, m, "biaxial", &w, err));
    double top = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        uint32_t *f = &s->flags[i];
        *f &= ~(uint32_t)CDEM_FLAG_MOVING;
        if (*f & CDEM_FLAG_WALL) {
            if (cdem_bc_is_base(&w, s, i))
                *f |= CDEM_FLAG_MOVING;
            else
                c->n_walls++;
        } else if (!(*f & CDEM_FLAGS_BOUNDARY)) {
            top = fmax(top, s->y[i] + s->radius[i]);
        }
    }
    if (!isfinite(top))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "biaxial: the assembly has no free elements");
    const double r = w.r_base;
    const double ext = 0.25 * (w.x_max - w.x_min);
    const long n_side = (long)ceil(ext / r);
    const double mass = p->density * M_PI * r * r;
    const uint32_t fl = CDEM_FLAG_WALL | CDEM_FLAG_MOVING | CDEM_FLAG_BASE;
    for (long k = 1; k <= n_side; k++) { /* bottom platen beyond both base ends */
        CDEM_TRY(cdem_state_append(s, -1, w.x_min - (double)k * r, w.y_base, r, mass, 0, fl, 0,
                                   NULL, err));
        CDEM_TRY(cdem_state_append(s, -1, w.x_max + (double)k * r, w.y_base, r, mass, 0, fl, 0,
                                   NULL, err));
        c->n_extend += 2;
    }
    c->r_bottom = c->r_top = r;
    c->y_bottom = w.y_base;
    c->y_top = top + r;
    const long n_top = (long)ceil((w.x_max - w.x_min + 2.0 * ext) / r);
    for (long k = 0; k <= n_top; k++) {
        CDEM_TRY(cdem_state_append(s, -1, w.x_min - ext + (double)k * r, c->y_top, r, mass, 0, fl,
                                   0, NULL, err));
        c->n_top++;
    }
    c->h0 = (c->y_top - r) - (c->y_bottom + r);
    if (!(c->h0 > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "biaxial: platen gap = %g m: must be > 0", c->h0);
    c->y_mid = 0.5 * (c->y_top + c->y_bottom);
    c->pressure = p->confining_pressure;
    c->equil = m->equil_steps;
    c->kn = m->kn > 0.0 ? m->kn : 1.0;
    const long interval = p->series_interval > 0 ? p->series_interval : 1;
    const double win = ceil(5.0 * m->display_steps / (double)interval);
    c->window = win >= 1.0 ? (win < 1e6 ? (size_t)win : 1000000) : 1;
    c->ring_f = calloc(c->window, sizeof *c->ring_f);
    c->ring_l = calloc(c->window, sizeof *c->ring_l);
    if (!c->ring_f || !c->ring_l)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "biaxial: out of memory for %zu averaging samples",
                         c->window);
    return CDEM_OK;
}

static cdem_status biaxial_equilibrate(void *vctx, cdem_state *s, double du, double dt,
                                       cdem_error *err);

/* k >= 1: a deformation step; k = 0: an equilibration step (moves_in_equilibration). */
static cdem_status biaxial_apply(void *vctx, cdem_state *s, long k, double du, double dt,
                                 cdem_error *err) {
    if (k <= 0)
        return biaxial_equilibrate(vctx, s, du, dt, err);
    biaxial_ctx *c = vctx;
    const double h = 0.5 * du, v = dt > 0.0 ? h / dt : 0.0;
    for (size_t i = 0; i < s->n; i++) {
        if (!is_platen(s->flags[i]))
            continue;
        const double sign = s->y[i] > c->y_mid ? -1.0 : 1.0;
        s->y[i] += sign * h;
        s->vx[i] = 0.0;
        s->vy[i] = sign * v;
    }
    c->y_top -= h;
    c->y_bottom += h;
    c->closure += du;
    return CDEM_OK;
}

/* Servo step of one platen: the contact force error (load - target, N, positive = the
 * sample pushes harder than the target) moves the platen outward by GAIN x error / (Kn x
 * platen contacts), at most du per step (never faster than the deformation). */
static double servo_move(double load, double target, long contacts, double kn, double du) {
    const double nc = contacts > 0 ? (double)contacts : 1.0;
    const double d = BIAXIAL_SERVO_GAIN * (load - target) / (kn * nc);
    const double cap = BIAXIAL_SERVO_SPEED * du;
    return d > cap ? cap : (d < -cap ? -cap : d);
}

static cdem_status biaxial_equilibrate(void *vctx, cdem_state *s, double du, double dt,
                                       cdem_error *err) {
    biaxial_ctx *c = vctx;
    if (!(dt > 0.0) || !(du > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "biaxial: equilibration step with dt = %g s, du = %g m: both must be > 0",
                         dt, du);
    c->eq_step++;
    double ft = 0.0, fb = 0.0, lo = INFINITY, hi = -INFINITY;
    long nt = 0, nb = 0;
    for (size_t i = 0; i < s->n; i++) { /* serial, fixed order: reproducible */
        const uint32_t f = s->flags[i];
        if (is_platen(f)) {
            if (s->y[i] > c->y_mid) {
                ft += s->fy[i];
                nt += s->fy[i] != 0.0;
            } else {
                fb += s->fy[i];
                nb += s->fy[i] != 0.0;
            }
        } else if (!(f & CDEM_FLAGS_BOUNDARY)) {
            lo = fmin(lo, s->x[i] - s->radius[i]);
            hi = fmax(hi, s->x[i] + s->radius[i]);
        }
    }
    const double width = hi > lo ? hi - lo : 0.0;
    c->servo = c->pressure * cdem_bc_confining_ramp(c->eq_step, c->equil);
    const double target = c->servo * width;
    /* top platen: pushed up (+y) by the sample; bottom: pushed down */
    const double dtop = servo_move(ft, target, nt, c->kn, du);
    const double dbot = servo_move(-fb, target, nb, c->kn, du);
    for (size_t i = 0; i < s->n; i++) {
        if (!is_platen(s->flags[i]))
            continue;
        const double d = s->y[i] > c->y_mid ? dtop : -dbot;
        s->y[i] += d;
        s->vx[i] = 0.0;
        s->vy[i] = d / dt;
    }
    c->y_top += dtop;
    c->y_bottom -= dbot;
    c->y_mid = 0.5 * (c->y_top + c->y_bottom);
    return CDEM_OK;
}

static cdem_status biaxial_begin(void *vctx, const cdem_state *s, unsigned char *keep,
                                 size_t *n_remove, cdem_error *err) {
    biaxial_ctx *c = vctx;
    c->h0 = (c->y_top - c->r_top) - (c->y_bottom + c->r_bottom);
    if (!(c->h0 > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "biaxial: platen gap at the start of deformation = %g m: must be > 0",
                         c->h0);
    size_t n = 0;
    for (size_t i = 0; i < s->n; i++)
        if ((s->flags[i] & CDEM_FLAG_WALL) && !(s->flags[i] & CDEM_FLAG_MOVING)) {
            keep[i] = 0;
            n++;
        }
    *n_remove = n;
    return CDEM_OK;
}

static double biaxial_net(const void *vctx) {
    return ((const biaxial_ctx *)vctx)->closure;
}

static void biaxial_measure(void *vctx, const cdem_state *s, long step, int sample,
                            double *axial_strain, double *differential_stress) {
    biaxial_ctx *c = vctx;
    *axial_strain = c->closure / c->h0;
    if (!sample) { /* an increment: the averages of the samples recorded so far */
        *differential_stress = c->have_ref ? c->last - c->ref : c->last;
        return;
    }
    double ft = 0.0, fb = 0.0, lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < s->n; i++) { /* serial, fixed order: reproducible */
        const uint32_t f = s->flags[i];
        if (is_platen(f)) {
            if (s->y[i] > c->y_mid)
                ft += s->fy[i];
            else
                fb += s->fy[i];
        } else if (!(f & CDEM_FLAGS_BOUNDARY)) {
            lo = fmin(lo, s->x[i] - s->radius[i]);
            hi = fmax(hi, s->x[i] + s->radius[i]);
        }
    }
    c->ring_f[c->head] = 0.5 * (fabs(ft) + fabs(fb));
    c->ring_l[c->head] = hi > lo ? hi - lo : 0.0;
    c->head = (c->head + 1) % c->window;
    if (c->n_ring < c->window)
        c->n_ring++;
    double sf = 0.0, sl = 0.0;
    for (size_t k = 0; k < c->n_ring; k++) {
        sf += c->ring_f[k];
        sl += c->ring_l[k];
    }
    const double axial = sl > 0.0 ? sf / sl : 0.0;
    const double diff = axial - c->pressure * cdem_bc_confining_ramp(step, c->equil);
    if (step >= c->equil && !c->have_ref) {
        c->ref = diff;
        c->have_ref = 1;
    }
    c->last = diff;
    *differential_stress = c->have_ref ? diff - c->ref : diff;
}

static void biaxial_view(const void *vctx, FILE *out) {
    const biaxial_ctx *c = vctx;
    fprintf(out,
            "Boundary mode: biaxial test, confining pressure %.6g N/m on the free edges (ramped "
            "from 0 at mid-equilibration to full at its end); top platen of %ld elements added "
            "at y = %.6g m, bottom platen = base (+%ld elements beyond its ends); platen "
            "contacts use material.wall_*; in equilibration the platens are servo-controlled to "
            "carry the same ramped "
            "pressure (isotropic start), then move toward each other at half the boundary "
            "speed each; the %ld lateral wall elements are removed at the start of "
            "deformation; initial sample height %.6g m (re-measured at the start of "
            "deformation); axial strain = closure / height; differential stress averaged over "
            "%zu samples (5 increments) and corrected to 0 at the end of equilibration.\n",
            c->pressure, c->n_top, c->y_top, c->n_extend, c->n_walls, c->h0, c->window);
}

static void biaxial_free(void *vctx) {
    biaxial_ctx *c = vctx;
    free(c->ring_f);
    free(c->ring_l);
    c->ring_f = c->ring_l = NULL;
}

/* Checkpoint: the platen heights and closure, the averaging window (ring buffers, fill,
 * head), the end-of-equilibration reference and the last sample evolve; the window length
 * and the initial gap are set by init (checked). */
static cdem_status biaxial_save(const void *vctx, cdem_snapshot *snap, cdem_error *err) {
    const biaxial_ctx *c = vctx;
    const char *P = "bc";
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "h0", c->h0, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "eq_step", (int64_t)c->eq_step, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "servo", c->servo, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "window", (int64_t)c->window, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "y_bottom", c->y_bottom, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "y_top", c->y_top, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "closure", c->closure, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "ring_f", CDEM_SNAP_F64, c->window, c->ring_f, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, P, "ring_l", CDEM_SNAP_F64, c->window, c->ring_l, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_ring", (int64_t)c->n_ring, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "head", (int64_t)c->head, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "have_ref", c->have_ref, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "ref", c->ref, err));
    return cdem_ckpt_put_f64(snap, P, "last", c->last, err);
}

static cdem_status biaxial_restore(void *vctx, const cdem_snapshot *snap, cdem_error *err) {
    biaxial_ctx *c = vctx;
    const char *P = "bc";
    /* h0 is re-measured at the start of deformation (servo platens move before it) */
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "h0", &c->h0, err));
    int64_t eq_step = 0;
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "eq_step", 0, (int64_t)c->equil, &eq_step, err));
    c->eq_step = (long)eq_step;
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "servo", &c->servo, err));
    int64_t window = 0, n_ring = 0, head = 0, have_ref = 0;
    CDEM_TRY(cdem_ckpt_get_i64(snap, P, "window", &window, err));
    if (window != (int64_t)c->window)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "checkpoint bc.window = %lld samples but this run averages over %zu: the "
                         "checkpoint belongs to another model",
                         (long long)window, c->window);
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "n_ring", 0, window, &n_ring, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "head", 0, window - 1, &head, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "have_ref", 0, 1, &have_ref, err));
    const cdem_snapshot_array *rf = NULL, *rl = NULL;
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "ring_f", CDEM_SNAP_F64, c->window, &rf, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "ring_l", CDEM_SNAP_F64, c->window, &rl, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "y_bottom", &c->y_bottom, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "y_top", &c->y_top, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "closure", &c->closure, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "ref", &c->ref, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "last", &c->last, err));
    memcpy(c->ring_f, rf->data, c->window * sizeof *c->ring_f);
    memcpy(c->ring_l, rl->data, c->window * sizeof *c->ring_l);
    c->n_ring = (size_t)n_ring;
    c->head = (size_t)head;
    c->have_ref = (int)have_ref;
    return CDEM_OK;
}

/* What the test cannot run with: a load on its top, and everything that makes the sample
 * other than one uniform material (heterogeneity, erosion, deposits, a physical process). */
static const char *const biaxial_excludes[] = {"surface.overburden_pressure",
                                               "heterogeneity.flexural_slip",
                                               "heterogeneity.weak_interval",
                                               "heterogeneity.layered_friction",
                                               "surface.erosion",
                                               "surface.sedimentation",
                                               CDEM_EXCLUDES_PROCESSES,
                                               NULL};

/* The test is defined on a 10 x 5 unit sample. */
static void biaxial_validate(const cdem_params *p, cdem_rule_log *log) {
    if (p->width == 10.0 && p->height == 5.0)
        return;
    char v1[64], v2[64];
    cdem_params_format_number(p->width, v1, sizeof v1);
    cdem_params_format_number(p->height, v2, sizeof v2);
    cdem_rule_add(log,
                  "mode = biaxial requires width = 10 and height = 5 units (got width = %s, "
                  "height = %s): set them in [assembly]",
                  v1, v2);
}

/* No gravity in the test, and a smooth bottom platen (one radius apart, like the top one), so
 * the two platens are alike and lubricated platens stay smooth. */
static void biaxial_derive(const cdem_params *p, cdem_model_mode *out) {
    (void)p;
    out->gravity_off = "off in the biaxial test";
    out->base_spacing = 1.0;
}

static void biaxial_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    cdem_summary_line(out, "confining pressure",
                      "%g N/m (%g MPa in 3-D), ramped from zero at %g s to full at %g s",
                      p->confining_pressure, p->confining_pressure / 1e6, 0.5 * p->equilibration,
                      p->equilibration);
    cdem_summary_line(out, "axial strain",
                      "%.4g at the end (platens shorten the %.6g m high sample)",
                      m->total_displacement / m->height_m, m->height_m);
    cdem_summary_line(out, "gravity", "off");
}

static const cdem_bc_ops biaxial_ops = {
    .state_size = sizeof(biaxial_ctx),  /* state_size */
    .init = biaxial_init,               /* adds the top platen */
    .apply = biaxial_apply,             /* moves both platens (servo in equilibration) */
    .moves_in_equilibration = 1,        /* servo platens: isotropic start */
    .boundary_only = 0,                 /* the servo reads the free elements' extent */
    .net_displacement = biaxial_net,    /* platen closure */
    .view = biaxial_view,               /* view */
    .free = biaxial_free,               /* averaging buffers */
    .begin_deformation = biaxial_begin, /* removes the lateral walls */
    .confined = 1,                      /* confining pressure on the free side edges */
    .measure = biaxial_measure,         /* axial strain, differential stress */
    .save = biaxial_save,               /* checkpoint: platens, window, reference */
    .restore = biaxial_restore,         /* resume */
    .validate = biaxial_validate,       /* the 10 x 5 sample */
    .excludes = biaxial_excludes,       /* overburden, heterogeneity, erosion, deposits,
                                           processes */
    .inverts = 0,                       /* the platens only close */
    .derive = biaxial_derive,           /* no gravity, smooth bottom platen */
    .describe = biaxial_describe,       /* pressure, strain, gravity */
};

const cdem_bc_ops *const cdem_bc_biaxial = &biaxial_ops;
