/* bc_listric: listric and irregular normal/reverse faults, constant heave (CH) or CD.
 *
 * Geometry (docs/solver.md, "Listric and irregular faults"): the left wall is sculpted into a
 * fault curve from (x0 = fault_location x width, 0) up-dip toward -x (dipping toward +x, the
 * hanging wall on the right): listric = dip(y) = d0 + (90 - d0) (y/H) from the base (d0 =
 * fault_dip) to the top of the assembly H (fault_file.h), irregular = the vertex file's
 * polyline. Fault elements (CDEM_FLAG_FAULT | MOVING, radius of the base elements, spaced by
 * one radius) lie on the curve, extended below the base along the basal segment for the whole
 * displacement plus 4 radii and vertically above its top to the top of the walls plus the
 * whole displacement. Free elements cut by the fault (closer to the curve than their radius
 * plus the fault radius, on either side) are removed; those left of it (entirely on the
 * footwall side of the fault elements) and the left wall become display-only footwall
 * elements (CDEM_FLAG_FOOTWALL; they never interact). The whole base moves with the hanging
 * wall, except its part left of x0 (below).
 * The base left of x0 is the footwall's base: it stays a wall (it bounds the escape test) but
 * moves with the footwall, not with the hanging wall (manual v4.1).
 * CH kinematics (Verrall 1981): relative to the footwall the hanging wall moves by the heave
 * du cos(db) horizontally and the throw du sin(db) vertically, db = dip of the basal segment,
 * and collapses by vertical shear onto the fault. In the model frame (hanging-wall base fixed
 * in x) the fault elements move horizontally by the heave AWAY from the hanging wall (-x for
 * normal, +x for reverse) and the hanging-wall base (the base, the right wall) vertically by
 * the throw (down for normal), so the base-fault junction stays at x = x0 and slides down
 * the basal segment by du per step; the footwall display elements move with the fault (the
 * footwall is rigid), so the fault is never drawn over them. Inversion as in
 * bc_planar_fault.c.
 * CD kinematics ("mylar sheet", kinematics = cd): the path stays fixed and the fault elements
 * (also CDEM_FLAG_MYLAR) slide along it by du per step (down-dip for normal); the base and
 * right wall move du along the basal segment.
 * One of several boundary actors (bc.h, docs/solver.md "Boundaries on a timeline"): the
 * footwall is another fault's block or part of one, so it stays live material and the frame is
 * the footwall's. Nothing is made display-only (the left wall stays a wall, the free elements
 * left of the curve stay free); the fault elements are fixed to the footwall (CH) or slide
 * along their path relative to it (CD, by the path's increments, so that a fault whose
 * footwall rides on another's hanging wall carries its curve along), and the base right of
 * x0 and the right wall move du along the basal segment per step (its model's moving flag),
 * adding their velocity to the other actors'. Its adopt hook takes the other actors' fault
 * elements right of its curve (below the base along the basal segment, above the curve's top
 * vertically). The relative motion of the two walls of the fault is the single run's. */
#include "bc.h"
#include "checkpoint.h"
#include "fault_file.h"
#include "summary_line.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int irregular;            /* 1: irregular-fault (vertex file), 0: listric-fault */
    double dip_base_deg;      /* dip of the basal segment, degrees, (0, 90] */
    int sense;                /* initial cdem_fault_sense */
    int inversion;            /* 1: the sense reverses after k_inversion */
    long k_inversion;         /* last deformation step of the initial sense */
    double x_fault;           /* m, x0: where the curve meets the base surface (y = 0) */
    double height;            /* m, H: top of the assembly (highest free element top) */
    double heave;             /* horizontal fault motion per metre along the basal segment */
    double throw_;            /* vertical base motion per metre along the basal segment */
    cdem_fault_polyline line; /* the fault curve from (x0, 0) up-dip (owned) */
    long n_fault;             /* fault elements added */
    long n_footwall;          /* elements flagged CDEM_FLAG_FOOTWALL */
    long n_cut;               /* free elements removed at init: cut by the fault elements */
    long n_base_moving;       /* wall elements of the moving hanging-wall base/right wall */
    long n_base_footwall;     /* base elements left of x0: the footwall's base (not MOVING) */
    double net;               /* m, net displacement along the basal segment (initial sense +) */
    int cd;                   /* 1: constant displacement (mylar sheet), 0: constant heave */
    size_t path_n;            /* vertices of the fault-element path (ramp, curve, top) */
    double *path_x, *path_y;  /* m, the path from the ramp bottom up (owned) */
    double *path_s;           /* m, arc length of each path vertex from the ramp bottom */
    double spacing;           /* m, arc spacing of the fault elements (the base radius) */
    int32_t first_id;         /* id of the first fault element; ids are consecutive */
    double sheet;             /* m, CD: arc offset of the sheet so far (down-dip negative) */
    /* this step's moves (step_begin): CD: base and right wall (bx, by); CH: fault and
     * footwall display (ux), base and right wall (uy); dt for the velocities */
    double step_bx, step_by, step_ux, step_uy, step_dt;
    int composed;           /* 1: one of several actors (the footwall's frame, see above) */
    uint32_t moving;        /* the flag of its block (cdem_bc_moving_flag) */
    double step_sheet_prev; /* m, CD: the sheet offset before this step (composed moves) */
} listric_ctx;

static const char *mode_name(const listric_ctx *c) {
    return c->irregular ? "irregular fault" : "listric fault";
}

/* Position at arc length a along the path (linear extrapolation beyond its ends). */
static void path_at(const listric_ctx *c, double a, double *x, double *y) {
    size_t k = 1;
    if (a >= c->path_s[c->path_n - 1]) {
        k = c->path_n - 1;
    } else if (a > 0.0) {
        size_t lo = 1, hi = c->path_n - 1; /* first vertex with path_s >= a */
        while (lo < hi) {
            const size_t mid = (lo + hi) / 2;
            if (c->path_s[mid] >= a)
                hi = mid;
            else
                lo = mid + 1;
        }
        k = lo;
    }
    const double len = c->path_s[k] - c->path_s[k - 1];
    const double t = len > 0.0 ? (a - c->path_s[k - 1]) / len : 0.0;
    *x = c->path_x[k - 1] + t * (c->path_x[k] - c->path_x[k - 1]);
    *y = c->path_y[k - 1] + t * (c->path_y[k] - c->path_y[k - 1]);
}

/* Builds the path ramp -> curve -> vertical top and lays fault elements every r along it
 * (element j at arc length j r). */
static cdem_status lay_fault(listric_ctx *c, const cdem_params *p, cdem_state *s, double r,
                             double ramp, double y_top, cdem_error *err) {
    const cdem_fault_polyline *pl = &c->line;
    const size_t nv = pl->n + 2;
    c->path_x = malloc(nv * sizeof *c->path_x);
    c->path_y = malloc(nv * sizeof *c->path_y);
    c->path_s = malloc(nv * sizeof *c->path_s);
    if (!c->path_x || !c->path_y || !c->path_s)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory for %zu path vertices",
                         mode_name(c), nv);
    c->path_n = nv;
    double *qx = c->path_x, *qy = c->path_y;
    const double db = c->dip_base_deg * M_PI / 180.0;
    qx[0] = pl->x[0] + ramp * cos(db);
    qy[0] = pl->y[0] - ramp * sin(db);
    for (size_t k = 0; k < pl->n; k++) {
        qx[k + 1] = pl->x[k];
        qy[k + 1] = pl->y[k];
    }
    qx[nv - 1] = pl->x[pl->n - 1];
    qy[nv - 1] = fmax(y_top, pl->y[pl->n - 1]);
    c->path_s[0] = 0.0;
    for (size_t k = 1; k < nv; k++)
        c->path_s[k] = c->path_s[k - 1] + hypot(qx[k] - qx[k - 1], qy[k] - qy[k - 1]);
    c->spacing = r;
    c->first_id = s->next_id;
    const double mass = p->density * M_PI * r * r;
    /* composed CH: the curve is fixed to its footwall (moved only by the actors that adopt it) */
    const uint32_t fl =
        c->composed ? CDEM_FLAG_FAULT | (c->cd ? (uint32_t)CDEM_FLAG_MYLAR | c->moving : 0u)
                    : CDEM_FLAG_FAULT | CDEM_FLAG_MOVING | (c->cd ? (uint32_t)CDEM_FLAG_MYLAR : 0u);
    const long n = (long)floor(c->path_s[nv - 1] / r) + 1;
    for (long j = 0; j < n; j++) {
        double x, y;
        path_at(c, (double)j * r, &x, &y);
        CDEM_TRY(
            cdem_state_append(s, c->first_id + (int32_t)j, x, y, r, mass, 0, fl, 0, NULL, err));
        c->n_fault++;
    }
    return CDEM_OK;
}

static cdem_status lay_fault(listric_ctx *c, const cdem_params *p, cdem_state *s, double r,
                             double ramp, double y_top, cdem_error *err);

/* init of one of several actors (the footwall's frame): the base right of x0 and the right
 * wall carry its moving flag, the free elements cut by the curve are removed, nothing else
 * changes; then the fault elements. */
static cdem_status composed_init(listric_ctx *c, const cdem_params *p, const cdem_model *m,
                                 cdem_state *s, const cdem_bc_walls *w, double wall_top,
                                 cdem_error *err) {
    c->sense = p->fault_sense;
    c->inversion = p->inversion ? 1 : 0;
    c->k_inversion = cdem_model_inversion_step(p, m);
    const double db = c->dip_base_deg * M_PI / 180.0;
    c->heave = cos(db);
    c->throw_ = sin(db);
    const double rf = w->r_base;
    unsigned char *keep = malloc(s->n ? s->n : 1);
    if (!keep)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory for %zu keep flags", mode_name(c),
                         s->n);
    memset(keep, 1, s->n);
    for (size_t i = 0; i < s->n; i++) {
        s->flags[i] &= ~c->moving;
        if (s->flags[i] & CDEM_FLAG_WALL) {
            const int is_base = cdem_bc_is_base(w, s, i);
            if ((is_base && s->x[i] >= c->x_fault) || (!is_base && s->x[i] > w->x_mid)) {
                s->flags[i] |= c->moving;
                c->n_base_moving++;
            } else if (is_base) {
                c->n_base_footwall++;
            }
        } else if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY) &&
                   cdem_fault_file_distance(&c->line, s->x[i], s->y[i]) < s->radius[i] + rf) {
            keep[i] = 0;
            c->n_cut++;
        }
    }
    if (c->n_cut > 0)
        cdem_state_compact(s, keep, NULL);
    free(keep);
    const double ramp = m->total_displacement + 4.0 * rf;
    return lay_fault(c, p, s, rf, ramp, fmax(wall_top, c->height) + m->total_displacement, err);
}

static cdem_status listric_init_common(listric_ctx *c, const cdem_params *p, const cdem_model *m,
                                       cdem_state *s, cdem_error *err) {
    const char *name = mode_name(c);
    c->cd = p->kinematics == CDEM_KIN_CD;
    if (!(p->fault_location > 0.0 && p->fault_location < 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "%s: boundary.fault_location = %g: must be in (0, 1)",
                         name, p->fault_location);
    if (p->inversion && !(p->inversion_percent >= 0.0 && p->inversion_percent <= 100.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "%s: boundary.inversion_percent = %g: must be in 0-100", name,
                         p->inversion_percent);
    cdem_bc_walls w;
    CDEM_TRY(cdem_bc_find_walls(s, m, name, &w, err));
    double top = -INFINITY, wall_top = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            wall_top = fmax(wall_top, s->y[i]);
        else
            top = fmax(top, s->y[i] + s->radius[i]);
    }
    if (!(top > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "%s: the assembly has no free element above the base (top = %g m)", name,
                         top);
    c->height = top;
    c->x_fault = p->fault_location * m->width_m;
    if (c->irregular) {
        CDEM_TRY(
            cdem_fault_file_read(p->fault_file, c->x_fault, 0.5 * m->radius[0], &c->line, err));
        /* the fault elements are laid along the curve up to its highest vertex (lay_fault): a
         * vertex at y = 1e9 m laid millions of them. Twice the model's height leaves room for
         * a vertex file written for a taller model of the same fault. */
        CDEM_TRY(cdem_fault_file_check_extent(&c->line, p->fault_file,
                                              2.0 * (fmax(wall_top, top) + m->total_displacement),
                                              0.5 * m->radius[0], err));
        c->dip_base_deg =
            atan2(c->line.y[1] - c->line.y[0], c->line.x[0] - c->line.x[1]) * 180.0 / M_PI;
    } else {
        if (!(p->fault_dip > 0.0 && p->fault_dip <= 90.0))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "%s: boundary.fault_dip = %g degrees: must be in (0, 90]", name,
                             p->fault_dip);
        CDEM_TRY(cdem_fault_file_listric(c->x_fault, c->height, p->fault_dip, CDEM_LISTRIC_SEGMENTS,
                                         &c->line, err));
        c->dip_base_deg = p->fault_dip;
    }
    const cdem_fault_polyline *pl = &c->line;
    c->composed = m->composed;
    c->moving = cdem_bc_moving_flag(m);
    if (c->composed)
        return composed_init(c, p, m, s, &w, wall_top, err);
    /* the fault moves up to the whole heave toward the left wall */
    const double x_left = pl->x[pl->n - 1];
    const double max_heave = m->total_displacement * cos(c->dip_base_deg * M_PI / 180.0);
    if (!(x_left - max_heave > w.x_min + 2.0 * w.r_base))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "%s: the fault curve reaches x = %g m at y = %g m and moves up to %g m "
                         "(the total heave) further toward the left wall (x = %g m): it would "
                         "reach or pass it; move boundary.fault_location right, steepen the "
                         "fault (fault_dip = %g degrees) or shorten the run",
                         name, x_left, pl->y[pl->n - 1], max_heave, w.x_min, c->dip_base_deg);
    c->sense = p->fault_sense;
    c->inversion = p->inversion ? 1 : 0;
    c->k_inversion = cdem_model_inversion_step(p, m);
    const double db = c->dip_base_deg * M_PI / 180.0;
    c->heave = cos(db);
    c->throw_ = sin(db);
    const double rf = w.r_base;
    /* footwall, hanging-wall base and right wall; elements cut by the fault are removed */
    unsigned char *keep = malloc(s->n ? s->n : 1);
    if (!keep)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "%s: out of memory for %zu keep flags", name, s->n);
    memset(keep, 1, s->n);
    for (size_t i = 0; i < s->n; i++) {
        uint32_t f = s->flags[i] & ~(uint32_t)CDEM_FLAG_MOVING;
        if (f & CDEM_FLAG_WALL) {
            const int is_base = cdem_bc_is_base(&w, s, i);
            if (!is_base && s->x[i] < w.x_mid) {
                f = (f & ~(uint32_t)CDEM_FLAG_WALL) | CDEM_FLAG_FOOTWALL; /* left wall */
                c->n_footwall++;
            } else if (is_base && s->x[i] < c->x_fault) {
                c->n_base_footwall++; /* the footwall's base: a wall, moves with the footwall */
            } else {
                f |= CDEM_FLAG_MOVING;
                c->n_base_moving++;
            }
        } else if (!(f & CDEM_FLAGS_BOUNDARY)) {
            const double xi = s->x[i], yi = s->y[i];
            if (cdem_fault_file_distance(pl, xi, yi) < s->radius[i] + rf) {
                keep[i] = 0; /* overlaps the fault elements: neither wall keeps it */
                c->n_cut++;
            } else if (xi < cdem_fault_file_x_at(pl, yi)) {
                f |= CDEM_FLAG_FOOTWALL;
                s->vx[i] = s->vy[i] = 0.0;
                c->n_footwall++;
            }
        }
        s->flags[i] = f;
    }
    if (c->n_cut > 0)
        cdem_state_compact(s, keep, NULL);
    free(keep);
    const double ramp = m->total_displacement + 4.0 * rf;
    return lay_fault(c, p, s, rf, ramp, fmax(wall_top, c->height) + m->total_displacement, err);
}

static cdem_status listric_init(void *vctx, const cdem_params *p, const cdem_model *m,
                                cdem_state *s, cdem_error *err) {
    listric_ctx *c = vctx;
    c->irregular = 0;
    return listric_init_common(c, p, m, s, err);
}

static cdem_status irregular_init(void *vctx, const cdem_params *p, const cdem_model *m,
                                  cdem_state *s, cdem_error *err) {
    listric_ctx *c = vctx;
    c->irregular = 1;
    return listric_init_common(c, p, m, s, err);
}

/* The step's once-only work: the sense, the moves kept for listric_step_move, the net
 * displacement. CD: the sheet (fault elements) slides along the fixed path by du per step
 * (down-dip for normal), the base and right wall move along the basal segment by du. CH:
 * the fault elements and the footwall display move by the heave, the hanging-wall base and
 * right wall by the throw. */
static cdem_status listric_step_begin(void *vctx, long k, double du, double dt, cdem_error *err) {
    listric_ctx *c = vctx;
    if (!(dt > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "%s: dt = %g s: must be > 0", mode_name(c), dt);
    const double sgn =
        ((k <= c->k_inversion) ? 1.0 : -1.0) * (c->sense == CDEM_SENSE_NORMAL ? 1.0 : -1.0);
    c->step_dt = dt;
    if (c->composed) { /* the footwall's frame: the base along the basal segment */
        c->step_sheet_prev = c->sheet;
        if (c->cd)
            c->sheet -= sgn * du;
        c->step_bx = sgn * du * c->heave;
        c->step_by = -sgn * du * c->throw_;
    } else if (c->cd) {
        c->sheet -= sgn * du;
        c->step_bx = sgn * du * c->heave;
        c->step_by = -sgn * du * c->throw_;
    } else {
        c->step_ux = -sgn * du * c->heave;
        c->step_uy = -sgn * du * c->throw_;
    }
    c->net += ((k <= c->k_inversion) ? 1.0 : -1.0) * du;
    return CDEM_OK;
}

static void cd_move(const listric_ctx *c, cdem_state *s, long lo, long hi) {
    const double bx = c->step_bx, by = c->step_by, dt = c->step_dt;
    for (long i = lo; i < hi; i++) {
        const uint32_t f = s->flags[i];
        if (!(f & CDEM_FLAG_MOVING))
            continue;
        if (f & CDEM_FLAG_MYLAR) {
            const double a = (double)(s->id[i] - c->first_id) * c->spacing + c->sheet;
            double x, y;
            path_at(c, a, &x, &y);
            s->vx[i] = (x - s->x[i]) / dt;
            s->vy[i] = (y - s->y[i]) / dt;
            s->x[i] = x;
            s->y[i] = y;
        } else {
            s->x[i] += bx;
            s->y[i] += by;
            s->vx[i] = bx / dt;
            s->vy[i] = by / dt;
        }
    }
}

/* The moves of one of several actors: the block by (bx, by); CD: its own sheet elements by
 * their path's increment (whatever the other actors moved them by). Velocities add. */
static void composed_move(const listric_ctx *c, cdem_state *s, long lo, long hi) {
    const double bx = c->step_bx, by = c->step_by, dt = c->step_dt;
    for (long i = lo; i < hi; i++) {
        const uint32_t f = s->flags[i];
        if (!(f & c->moving))
            continue;
        double ux = bx, uy = by;
        if ((f & CDEM_FLAG_MYLAR) && s->id[i] >= c->first_id &&
            s->id[i] < c->first_id + (int32_t)c->n_fault) {
            const double a = (double)(s->id[i] - c->first_id) * c->spacing;
            double x0, y0, x1, y1;
            path_at(c, a + c->step_sheet_prev, &x0, &y0);
            path_at(c, a + c->sheet, &x1, &y1);
            ux = x1 - x0;
            uy = y1 - y0;
        }
        s->x[i] += ux;
        s->y[i] += uy;
        s->vx[i] += ux / dt;
        s->vy[i] += uy / dt;
    }
}

static void listric_step_move(const void *vctx, cdem_state *s, long lo, long hi) {
    const listric_ctx *c = vctx;
    if (c->composed) {
        composed_move(c, s, lo, hi);
        return;
    }
    if (c->cd) {
        cd_move(c, s, lo, hi);
        return;
    }
    const double ux = c->step_ux, uy = c->step_uy;
    const double vx = ux / c->step_dt, vy = uy / c->step_dt;
    double *restrict x = s->x, *restrict y = s->y, *restrict vxa = s->vx, *restrict vya = s->vy;
    const uint32_t *restrict fl = s->flags;
    for (long i = lo; i < hi; i++) {
        if ((fl[i] & CDEM_FLAG_FOOTWALL) ||
            (fl[i] & (CDEM_FLAG_WALL | CDEM_FLAG_MOVING)) == CDEM_FLAG_WALL) {
            x[i] += ux; /* footwall display and footwall base: ride with the fault */
            continue;
        }
        if (!(fl[i] & CDEM_FLAG_MOVING))
            continue;
        if (fl[i] & CDEM_FLAG_FAULT) {
            x[i] += ux;
            vxa[i] = vx;
            vya[i] = 0.0;
        } else {
            y[i] += uy;
            vxa[i] = 0.0;
            vya[i] = vy;
        }
    }
}

/* The other actors' fault elements right of the curve join the block (x_at: below the base
 * along the basal segment, above the curve's top vertically). */
static void listric_adopt(void *vctx, cdem_state *s) {
    listric_ctx *c = vctx;
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_FAULT) || (s->flags[i] & c->moving) ||
            (s->id[i] >= c->first_id && s->id[i] < c->first_id + (int32_t)c->n_fault))
            continue;
        if (s->x[i] > cdem_fault_file_x_at(&c->line, s->y[i])) {
            s->flags[i] |= c->moving;
            c->n_base_moving++;
        }
    }
}

/* The traces: the built-in curve, or the vertex file's. */
static cdem_status listric_trace(const cdem_params *p, const cdem_model *m, double height,
                                 cdem_fault_polyline *out, cdem_error *err) {
    return cdem_fault_file_listric(p->fault_location * m->width_m, height, p->fault_dip,
                                   CDEM_LISTRIC_SEGMENTS, out, err);
}

static cdem_status irregular_trace(const cdem_params *p, const cdem_model *m, double height,
                                   cdem_fault_polyline *out, cdem_error *err) {
    (void)height;
    return cdem_fault_file_read(p->fault_file, p->fault_location * m->width_m, 0.5 * m->radius[0],
                                out, err);
}

static double listric_net(const void *vctx) {
    return ((const listric_ctx *)vctx)->net;
}

static void listric_view(const void *vctx, FILE *out) {
    const listric_ctx *c = vctx;
    fprintf(out,
            "Boundary mode: %s %s, %s; from the base at x = %.1f m up-dip toward -x to "
            "x = %.1f m at y = %.1f m (%zu vertices%s); basal dip %.1f deg; ",
            c->irregular ? "irregular" : "listric",
            c->sense == CDEM_SENSE_NORMAL ? "normal fault" : "reverse fault",
            c->cd ? "constant displacement (CD, mylar sheet)" : "constant heave (CH)", c->x_fault,
            c->line.x[c->line.n - 1], c->line.y[c->line.n - 1], c->line.n,
            c->irregular ? ", from the fault file" : ", dip = d0 + (90 - d0) y/H", c->dip_base_deg);
    if (c->composed)
        fprintf(out,
                "one of several boundary actors, in its footwall's frame: per metre of "
                "displacement the base right of the fault and the right wall move (%.4f, %.4f) m "
                "along the basal segment%s; the footwall stays live material; ",
                c->heave, -c->throw_,
                c->cd ? " and the fault elements slide 1 m along the fault"
                      : ", the fault elements stay with the footwall");
    else if (c->cd)
        fprintf(out,
                "per metre of displacement the fault elements slide 1 m along the fault and "
                "the base and right wall move (%.4f, %.4f) m along the basal segment; ",
                c->heave, -c->throw_);
    else
        fprintf(out,
                "per metre along the basal segment the fault moves %.4f m horizontally away "
                "from the hanging wall and the hanging-wall base %.4f m vertically; ",
                c->heave, c->throw_);
    fprintf(out,
            "%ld fault elements, %ld footwall display elements and %ld footwall base elements%s, "
            "%ld free elements cut by the fault removed, %ld moving base/right-wall elements.",
            c->n_fault, c->n_footwall, c->n_base_footwall,
            c->cd ? " (fixed)" : " (moving with the fault)", c->n_cut, c->n_base_moving);
    if (c->inversion)
        fprintf(out, " Inversion after deformation step %ld.", c->k_inversion);
    fprintf(out, "\n");
}

static void listric_free(void *vctx) {
    listric_ctx *c = vctx;
    cdem_fault_file_free(&c->line);
    free(c->path_x);
    free(c->path_y);
    free(c->path_s);
    c->path_x = c->path_y = c->path_s = NULL;
}

/* Checkpoint: the net displacement and (CD) the sheet offset evolve; the curve, the path and
 * the fault elements are set by init on the same assembly (x_fault, first_id checked). */
static cdem_status listric_save(const void *vctx, cdem_snapshot *snap, cdem_error *err) {
    const listric_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "x_fault", c->x_fault, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, "bc", "first_id", c->first_id, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, "bc", "line_x", CDEM_SNAP_F64, c->line.n, c->line.x, err));
    CDEM_TRY(cdem_ckpt_put_array(snap, "bc", "line_y", CDEM_SNAP_F64, c->line.n, c->line.y, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, "bc", "net", c->net, err));
    return cdem_ckpt_put_f64(snap, "bc", "sheet", c->sheet, err);
}

static cdem_status listric_restore(void *vctx, const cdem_snapshot *snap, cdem_error *err) {
    listric_ctx *c = vctx;
    CDEM_TRY(cdem_ckpt_check_f64(snap, "bc", "x_fault", c->x_fault, err));
    int64_t first = 0;
    CDEM_TRY(cdem_ckpt_get_i64(snap, "bc", "first_id", &first, err));
    if (first != c->first_id)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "checkpoint bc.first_id = %lld but this run's first fault element has id "
                         "%d: the checkpoint belongs to another model",
                         (long long)first, (int)c->first_id);
    /* the fault curve (for irregular faults re-read from the vertex file) must be the same */
    const cdem_snapshot_array *lx = NULL, *ly = NULL;
    CDEM_TRY(cdem_ckpt_get_array(snap, "bc", "line_x", CDEM_SNAP_F64, SIZE_MAX, &lx, err));
    CDEM_TRY(cdem_ckpt_get_array(snap, "bc", "line_y", CDEM_SNAP_F64, lx->count, &ly, err));
    if (lx->count != c->line.n || memcmp(lx->data, c->line.x, c->line.n * sizeof(double)) != 0 ||
        memcmp(ly->data, c->line.y, c->line.n * sizeof(double)) != 0)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "%s: the fault curve of the checkpoint (%zu vertices) differs from this "
                         "run's (%zu vertices%s): the checkpoint belongs to another fault",
                         mode_name(c), lx->count, c->line.n,
                         c->irregular ? ", read again from boundary.fault_file" : "");
    CDEM_TRY(cdem_ckpt_get_f64(snap, "bc", "net", &c->net, err));
    return cdem_ckpt_get_f64(snap, "bc", "sheet", &c->sheet, err);
}

/* The summary's lines after the fault's shape: the kinematics, the footwall, the inversion. */
static void describe_rest(const cdem_params *p, const cdem_model *m, FILE *out) {
    cdem_summary_line(out, "kinematics", "%s",
                      p->kinematics == CDEM_KIN_CD ? "constant displacement (CD, mylar sheet)"
                                                   : "constant heave (CH)");
    if (m->composed)
        cdem_summary_line(out, "footwall",
                          "live material, fixed (the frame of the footwall: one of several "
                          "boundary actors)");
    else
        cdem_summary_line(out, "footwall", "removed (hanging-wall deformation only)");
    cdem_bc_describe_inversion(p, m, out);
}

static void listric_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    cdem_bc_describe_fault(p, m, out);
    cdem_summary_line(out, "fault dip", "%g degrees at the base, steepening to 90 degrees",
                      p->fault_dip);
    describe_rest(p, m, out);
}

static void irregular_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    cdem_bc_describe_fault(p, m, out);
    cdem_summary_line(out, "fault vertices", "%s (x y in m, from the base up-dip)", p->fault_file);
    describe_rest(p, m, out);
}

/* irregular-fault: the vertex file is required, and it is an input of the run. */
static void irregular_validate(const cdem_params *p, cdem_rule_log *log) {
    if (p->fault_file[0] == '\0')
        cdem_rule_add(log, "mode = irregular-fault requires fault_file: set [boundary] "
                           "fault_file to a text file of x y vertices in m");
}

static void irregular_derive(const cdem_params *p, cdem_model_mode *out) {
    out->input = p->fault_file;
    out->input_what = "the fault vertex file (boundary.fault_file)";
}

static const cdem_bc_ops listric_ops = {
    .state_size = sizeof(listric_ctx),
    .init = listric_init,
    .step_begin = listric_step_begin, /* apply, split: the sense, the net displacement */
    .step_move = listric_step_move,   /* and the fault, wall and footwall elements */
    .boundary_only = 1,               /* fault, mylar, wall and footwall-display elements only */
    .net_displacement = listric_net,
    .view = listric_view,
    .free = listric_free,
    .save = listric_save,
    .restore = listric_restore,
    .validate = NULL, /* the built-in curve needs no rule */
    .excludes = NULL,
    .inverts = 1,
    .derive = NULL,
    .describe = listric_describe,
    .composes = 1,          /* one of several actors: the footwall's frame (above) */
    .adopt = listric_adopt, /* the other actors' fault elements right of its curve */
    .trace = listric_trace, /* its curve, for the checks of several faults */
};

static const cdem_bc_ops irregular_ops = {
    .state_size = sizeof(listric_ctx),
    .init = irregular_init,
    .step_begin = listric_step_begin, /* apply, split: the sense, the net displacement */
    .step_move = listric_step_move,   /* and the fault, wall and footwall elements */
    .boundary_only = 1,               /* fault, mylar, wall and footwall-display elements only */
    .net_displacement = listric_net,
    .view = listric_view,
    .free = listric_free,
    .save = listric_save,
    .restore = listric_restore,
    .validate = irregular_validate, /* the vertex file is required */
    .excludes = NULL,
    .inverts = 1,
    .derive = irregular_derive, /* the vertex file is an input of the run */
    .describe = irregular_describe,
    .composes = 1,
    .adopt = listric_adopt,
    .trace = irregular_trace,
};

const cdem_bc_ops *const cdem_bc_listric_fault = &listric_ops;
const cdem_bc_ops *const cdem_bc_irregular_fault = &irregular_ops;
