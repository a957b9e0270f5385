/* fault_timeline: the actors of a run and the activity of their fault zones (the header's
 * note says how). */
#include "fault_timeline.h"

#include "strain.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The boundary's acceleration (m/s^2): the displacement per step is 25 dt^2
 * (CDEM_BOUNDARY_ACCEL, solver/base/model.h; the analysis does not link the solver). */
#define BOUNDARY_ACCEL 25.0
/* Heights at which a trace is tabulated over the zone (0 .. H/2). */
#define TRACE_ROWS 64

int cdem_timeline_actors(const cdem_params *p, cdem_timeline_actor *out) {
    const int n = cdem_params_actor_count(p);
    int k = 0;
    for (int j = 0; j < n && j < CDEM_BOUNDARY_ACTORS; j++) {
        cdem_params pj;
        if (cdem_params_actor(p, j, &pj, NULL) != CDEM_OK)
            continue;
        cdem_timeline_actor *t = &out[k++];
        memset(t, 0, sizeof *t);
        snprintf(t->section, sizeof t->section, j == 0 ? "[boundary]" : "[boundary.%d]", j + 1);
        t->mode = pj.mode;
        t->fault = pj.mode == CDEM_MODE_PLANAR_FAULT || pj.mode == CDEM_MODE_LISTRIC_FAULT ||
                   pj.mode == CDEM_MODE_IRREGULAR_FAULT;
        t->listric = pj.mode == CDEM_MODE_LISTRIC_FAULT;
        t->x_base = pj.fault_location * pj.width * pj.unit_scaling;
        t->dip_deg = pj.fault_dip;
        t->start = pj.window_start;
        t->stop = pj.window_stop;
    }
    return k;
}

double cdem_timeline_run_displacement(const cdem_analysis *a, size_t index) {
    if (!cdem_analysis_equil_known(a))
        return 0.0;
    const size_t e = cdem_analysis_equil_index(a);
    if (index <= e)
        return 0.0;
    const cdem_increment_info *in = cdem_analysis_info(a, index), *eq = cdem_analysis_info(a, e);
    if (in->step <= 0)
        return 0.0;
    const double dt = in->time / (double)in->step;
    return (double)(in->step - eq->step) * BOUNDARY_ACCEL * dt * dt;
}

double cdem_timeline_actor_displacement(const cdem_timeline_actor *t, double run) {
    const double end = t->stop > 0.0 ? fmin(run, t->stop) : run;
    return end > t->start ? end - t->start : 0.0;
}

void cdem_timeline_default_options(cdem_timeline_options *o) {
    o->band = 0.0;
    o->contrast = 3.0;
}

void cdem_timeline_free(cdem_timeline_result *res) {
    if (!res)
        return;
    free(res->number);
    free(res->run);
    free(res->score);
    free(res->active);
    memset(res, 0, sizeof *res);
}

/* x of actor t's trace at height y (m) above the base, H the assembly's height. */
static double trace_x(const cdem_timeline_actor *t, double y, double height) {
    const double d0 = t->dip_deg * M_PI / 180.0;
    if (!t->listric)
        return t->x_base - y * cos(d0) / sin(d0);
    const int n = 32; /* midpoint rule over the linear dip law */
    double x = t->x_base;
    for (int k = 0; k < n; k++) {
        const double ym = y * ((double)k + 0.5) / n;
        const double d = d0 + (0.5 * M_PI - d0) * fmin(1.0, ym / height);
        x -= (y / n) * cos(d) / sin(d);
    }
    return x;
}

/* The id of the base element just left of x in s (-1 without one). */
static int32_t base_left_of(const cdem_state *s, double x) {
    double ymin = INFINITY, rmin = INFINITY;
    for (size_t i = 0; i < s->n; i++)
        if (s->flags[i] & CDEM_FLAG_WALL) {
            ymin = fmin(ymin, s->y[i]);
            rmin = fmin(rmin, s->radius[i]);
        }
    int32_t id = -1;
    double best = -INFINITY;
    for (size_t i = 0; i < s->n; i++)
        if ((s->flags[i] & CDEM_FLAG_WALL) && s->y[i] <= ymin + 0.5 * rmin && s->x[i] < x &&
            s->x[i] > best) {
            best = s->x[i];
            id = s->id[i];
        }
    return id;
}

static int find_id(const cdem_state *s, int32_t id, double *x, double *y) {
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == id) {
            *x = s->x[i];
            *y = s->y[i];
            return 1;
        }
    return 0;
}

/* The run's geometry at increment 0: H, each fault's footwall base element and its start. */
typedef struct {
    double height, max_radius;
    int32_t anchor[CDEM_BOUNDARY_ACTORS];
    double ax0[CDEM_BOUNDARY_ACTORS], ay0[CDEM_BOUNDARY_ACTORS];
    double table[CDEM_BOUNDARY_ACTORS][TRACE_ROWS + 1]; /* trace x at heights 0 .. H/2 */
} geometry;

static cdem_status geometry_of(cdem_analysis *a, const cdem_timeline_result *res, geometry *g,
                               cdem_error *err) {
    const cdem_state *s0 = NULL;
    CDEM_TRY(cdem_analysis_state(a, 0, &s0, err));
    g->height = g->max_radius = 0.0;
    for (size_t i = 0; i < s0->n; i++)
        if (!(s0->flags[i] & CDEM_FLAGS_BOUNDARY)) {
            g->height = fmax(g->height, s0->y[i] + s0->radius[i]);
            g->max_radius = fmax(g->max_radius, s0->radius[i]);
        }
    if (!(g->height > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "the run has no free element in increment 0");
    for (int j = 0; j < res->n_actors; j++) {
        const cdem_timeline_actor *t = &res->actor[j];
        g->anchor[j] = base_left_of(s0, t->x_base);
        g->ax0[j] = g->ay0[j] = 0.0;
        if (g->anchor[j] >= 0)
            find_id(s0, g->anchor[j], &g->ax0[j], &g->ay0[j]);
        for (int r = 0; r <= TRACE_ROWS; r++)
            g->table[j][r] = trace_x(t, 0.5 * g->height * r / TRACE_ROWS, g->height);
    }
    return CDEM_OK;
}

/* Mean of v over the free elements of s in fault j's zone (NAN when none). */
static double zone_score(const geometry *g, int j, const cdem_state *s, const double *v,
                         double band) {
    double dx = 0.0, dy = 0.0, x, y;
    if (g->anchor[j] >= 0 && find_id(s, g->anchor[j], &x, &y)) {
        dx = x - g->ax0[j];
        dy = y - g->ay0[j];
    }
    const double top = 0.5 * g->height;
    double sum = 0.0;
    long n = 0;
    for (size_t i = 0; i < s->n; i++) {
        if ((s->flags[i] & CDEM_FLAGS_BOUNDARY) || !isfinite(v[i]))
            continue;
        const double yr = s->y[i] - dy;
        if (yr < 0.0 || yr > top)
            continue;
        const double f = yr / top * TRACE_ROWS;
        const int r = (int)fmin(f, TRACE_ROWS - 1);
        const double xt = g->table[j][r] + (f - r) * (g->table[j][r + 1] - g->table[j][r]);
        if (fabs(s->x[i] - dx - xt) < band) {
            sum += v[i];
            n++;
        }
    }
    return n > 0 ? sum / (double)n : NAN;
}

static int cmp_double(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of v over the free elements of s in the lower half of the assembly (NAN when
 * none): the strain of the increment away from its faults. */
static double background(const geometry *g, const cdem_state *s, const double *v, double *buf) {
    size_t n = 0;
    for (size_t i = 0; i < s->n; i++)
        if (!(s->flags[i] & CDEM_FLAGS_BOUNDARY) && isfinite(v[i]) && s->y[i] >= 0.0 &&
            s->y[i] <= 0.5 * g->height)
            buf[n++] = v[i];
    if (n == 0)
        return NAN;
    qsort(buf, n, sizeof *buf, cmp_double);
    return n % 2 ? buf[n / 2] : 0.5 * (buf[n / 2 - 1] + buf[n / 2]);
}

/* The increments whose interval (run displacement of the one before, its own] overlaps
 * actor t's window. */
static void window_increments(const cdem_timeline_result *res, const cdem_timeline_actor *t,
                              double prev_run, int *first, int *last) {
    *first = *last = -1;
    const double stop = t->stop > 0.0 ? t->stop : INFINITY;
    double before = prev_run;
    for (size_t k = 0; k < res->n_inc; k++) {
        /* a window that reaches into an increment by a rounding of the steps does not count */
        const double eps = 0.01 * (res->run[k] - before);
        if (res->run[k] > t->start + eps && before < stop - eps) {
            if (*first < 0)
                *first = res->number[k];
            *last = res->number[k];
        }
        before = res->run[k];
    }
}

cdem_status cdem_timeline_measure(cdem_analysis *a, const cdem_timeline_options *o,
                                  cdem_timeline_result *res, cdem_error *err) {
    memset(res, 0, sizeof *res);
    cdem_timeline_actor all[CDEM_BOUNDARY_ACTORS];
    const int n = cdem_timeline_actors(cdem_analysis_params(a), all);
    for (int j = 0; j < n; j++)
        if (all[j].fault)
            res->actor[res->n_actors++] = all[j];
    if (res->n_actors == 0)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                         "the run has no fault among its boundary actors (planar-fault, "
                         "listric-fault or irregular-fault)");
    if (!cdem_analysis_equil_known(a))
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "the run has no deformation increment yet");
    const size_t e = cdem_analysis_equil_index(a), count = cdem_analysis_count(a);
    if (count <= e + 1)
        return CDEM_FAIL(err, CDEM_ERR_NOTFOUND, "the run has no deformation increment yet");
    if (!(o->contrast > 1.0))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "activity contrast %g: must be > 1", o->contrast);
    geometry g;
    CDEM_TRY(geometry_of(a, res, &g, err));
    double band = o->band;
    if (!(band > 0.0)) {
        band = 2.0 * g.max_radius;
        for (int i = 0; i < res->n_actors; i++)
            for (int j = i + 1; j < res->n_actors; j++)
                band = fmin(band, 0.25 * fabs(res->actor[i].x_base - res->actor[j].x_base));
    }
    res->band = band;
    const int na = res->n_actors;
    res->n_inc = count - e - 1;
    res->number = calloc(res->n_inc, sizeof *res->number);
    res->run = calloc(res->n_inc, sizeof *res->run);
    res->score = calloc(res->n_inc * (size_t)na, sizeof *res->score);
    res->active = calloc(res->n_inc * (size_t)na, 1);
    if (!res->number || !res->run || !res->score || !res->active) {
        cdem_timeline_free(res);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the fault timeline");
    }
    for (int j = 0; j < na; j++)
        res->first_active[j] = res->last_active[j] = -1;
    for (size_t k = 0; k < res->n_inc; k++) {
        const size_t index = e + 1 + k;
        res->number[k] = cdem_analysis_info(a, index)->number;
        res->run[k] = cdem_timeline_run_displacement(a, index);
        /* the strain of this increment alone (incr-max-shear is over 5 increments) */
        const cdem_state *prev = NULL, *s = NULL;
        cdem_status st = cdem_analysis_state(a, index - 1, &prev, err);
        if (st == CDEM_OK)
            st = cdem_analysis_state(a, index, &s, err);
        const size_t cap = st == CDEM_OK && s->n ? s->n : 1;
        cdem_strain_measures *m = st == CDEM_OK ? malloc(cap * sizeof *m) : NULL;
        double *v = st == CDEM_OK ? malloc(cap * sizeof *v) : NULL;
        double *buf = st == CDEM_OK ? malloc(cap * sizeof *buf) : NULL;
        if (st == CDEM_OK && (!m || !v || !buf))
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the fault timeline");
        if (st == CDEM_OK)
            st = cdem_strain_compute(prev, s, NULL, 0.0, m, err);
        if (st != CDEM_OK) {
            free(m);
            free(v);
            free(buf);
            cdem_timeline_free(res);
            return st;
        }
        for (size_t i = 0; i < s->n; i++)
            v[i] = m[i].max_shear;
        free(m);
        const double bg = background(&g, s, v, buf);
        free(buf);
        for (int j = 0; j < na; j++) {
            const double z = zone_score(&g, j, s, v, band);
            const double c = bg > 0.0 ? z / bg : NAN;
            const size_t at = k * (size_t)na + (size_t)j;
            res->score[at] = c;
            res->active[at] = (unsigned char)(isfinite(c) && c >= o->contrast);
            if (res->active[at]) {
                if (res->first_active[j] < 0)
                    res->first_active[j] = res->number[k];
                res->last_active[j] = res->number[k];
            }
        }
        free(v);
    }
    for (int j = 0; j < na; j++)
        window_increments(res, &res->actor[j], 0.0, &res->first_window[j], &res->last_window[j]);
    return CDEM_OK;
}
