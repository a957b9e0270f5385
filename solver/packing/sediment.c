/* sediment: see sediment.h. The deposit uses a column grid (width 2 x max radius) over the
 * free-element span: the elements present before the deposit are listed per column (CSR),
 * discs deposited in this event are chained per column; a dropped disc at x with radius r
 * rests at the highest centre height yj + sqrt((r + rj)^2 - dx^2) over the elements j with
 * |dx| < r + rj, which touches its support and overlaps nothing. */
#include "sediment.h"

#include "checkpoint.h"
#include "grid.h"
#include "surface.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Offset of the deposit RNG seed from the assembly seed (independent streams). */
#define SEED_XOR 0x5ed1UL

/* Rounds v to 4 significant digits towards +inf (up = 1) or -inf (up = 0) and formats it, so
 * that advice such as "at least X" is itself sufficient. */
static void format_safe(double v, int up, char *buf, size_t n) {
    if (!(v > 0) || !isfinite(v)) {
        snprintf(buf, n, "%g", v);
        return;
    }
    double mag = pow(10.0, floor(log10(v)) - 3.0);
    double r = (up ? ceil(v / mag) : floor(v / mag)) * mag;
    snprintf(buf, n, "%.4g", r);
}

void cdem_sediment_rules(const cdem_params *p, cdem_rule_log *log) {
    if (!p->sedimentation)
        return;
    cdem_model m;
    cdem_error merr;
    cdem_error_clear(&merr);
    if (cdem_bc_derive_model(p, &m, &merr) != CDEM_OK) {
        cdem_rule_add(log, "%s", merr.msg);
        return;
    }
    const double settling = 0.2 * p->equilibration;
    const double between = m.sediment_interval / m.boundary_speed;
    if (!(settling > between))
        return;
    char s_set[32], s_bet[32], s_speed[32], s_di[32], s_eq[32], v1[64], v2[64];
    cdem_params_format_number(settling, s_set, sizeof s_set);
    snprintf(s_bet, sizeof s_bet, "%.4g", between);
    snprintf(s_speed, sizeof s_speed, "%.4g", m.boundary_speed);
    /* smallest display interval / largest equilibration that satisfy the rule */
    format_safe(settling * m.boundary_speed / 30.0, 1, s_di, sizeof s_di);
    format_safe(between / 0.2, 0, s_eq, sizeof s_eq);
    cdem_params_format_number(p->display_interval, v1, sizeof v1);
    cdem_params_format_number(p->equilibration, v2, sizeof v2);
    cdem_rule_add(log,
                  "settling > displacement: the settling time 0.2 x equilibration = 0.2 x %s s = "
                  "%s s is longer than the time between sediment steps 30 x display_interval / "
                  "boundary speed = 30 x %s m / %s m/s = %s s: increase [time] display_interval "
                  "to at least %s m or reduce [time] equilibration to at most %s s",
                  v2, s_set, v1, s_speed, s_bet, s_di, s_eq);
}

cdem_status cdem_sediment_init(cdem_sediment *sd, const cdem_params *p, const cdem_model *m,
                               cdem_error *err) {
    memset(sd, 0, sizeof *sd);
    sd->ymax0 = NAN;
    sd->event_step = -1;
    sd->settle_end = -1;
    if (!p->sedimentation)
        return CDEM_OK;
    for (int k = 0; k < CDEM_NUM_RADII; k++) {
        if (!(m->radius[k] > 0.0) || !isfinite(m->radius[k]) || !(m->mass[k] > 0.0) ||
            (k > 0 && m->radius[k] < m->radius[k - 1]))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "sediment: model radius[%d] = %g m, mass %g kg/m: radii must be "
                             "finite, > 0 and ascending, masses > 0",
                             k, m->radius[k], m->mass[k]);
        sd->radius[k] = m->radius[k];
        sd->mass[k] = m->mass[k];
    }
    if (m->sediment_steps < 1 || m->settling_steps < 0 || !(m->displacement_per_step > 0.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "sediment: sediment_steps = %ld (>= 1), settling_steps = %ld (>= 0), "
                         "displacement per step %g m (> 0): check [time] display_interval and "
                         "equilibration",
                         m->sediment_steps, m->settling_steps, m->displacement_per_step);
    sd->rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!sd->rng)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "sediment: out of memory for the RNG");
    gsl_rng_set(sd->rng, (unsigned long)p->seed ^ SEED_XOR);
    sd->enabled = 1;
    sd->du = m->displacement_per_step;
    sd->factor = m->sea_level_factor;
    sd->equil_steps = m->equil_steps;
    sd->total_steps = m->total_steps;
    sd->sediment_steps = m->sediment_steps;
    sd->settling_steps = m->settling_steps;
    return CDEM_OK;
}

void cdem_sediment_free(cdem_sediment *sd) {
    if (!sd)
        return;
    if (sd->rng)
        gsl_rng_free(sd->rng);
    free(sd->col_start);
    free(sd->col_items);
    free(sd->col_of);
    free(sd->col_head);
    free(sd->next_new);
    memset(sd, 0, sizeof *sd);
    sd->ymax0 = NAN;
    sd->event_step = -1;
    sd->settle_end = -1;
}

void cdem_sediment_begin(cdem_sediment *sd, const cdem_state *s) {
    if (!sd->enabled)
        return;
    const double top = cdem_surface_top(s);
    sd->ymax0 = isfinite(top) ? top : NAN;
}

double cdem_sediment_sea_level(const cdem_sediment *sd, long step) {
    if (!sd->enabled || step < sd->equil_steps || !isfinite(sd->ymax0))
        return NAN;
    return sd->ymax0 + (double)(step - sd->equil_steps) * sd->du * sd->factor;
}

int cdem_sediment_settling(const cdem_sediment *sd, long step) {
    return sd->enabled && sd->event_step >= 0 && step > sd->event_step && step <= sd->settle_end;
}

int cdem_sediment_due(const cdem_sediment *sd, long step) {
    if (!sd->enabled || step <= sd->equil_steps || !isfinite(sd->ymax0))
        return 0;
    if ((step - sd->equil_steps) % sd->sediment_steps != 0)
        return 0;
    if (step < sd->settle_end) /* the previous deposit is still settling */
        return 0;
    return step + sd->settling_steps <= sd->total_steps;
}

static cdem_status grow_i32(int32_t **a, size_t *cap, size_t need, cdem_error *err) {
    if (need <= *cap)
        return CDEM_OK;
    const size_t c = need + need / 2 + 16;
    int32_t *q = realloc(*a, c * sizeof *q);
    if (!q)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "sediment: out of memory (%zu entries)", c);
    *a = q;
    *cap = c;
    return CDEM_OK;
}

/* A radius class drawn with the classes' number shares (CDEM_RADIUS_SHARES, solver/base/model.h):
 * one uniform draw below the shares' sum, placed among their running sums. */
static int draw_class(gsl_rng *rng) {
    static const int shares[CDEM_NUM_RADII] = CDEM_RADIUS_SHARES;
    unsigned long u = gsl_rng_uniform_int(rng, CDEM_RADIUS_SHARES_TOTAL);
    int k = 0;
    while (k + 1 < CDEM_NUM_RADII && u >= (unsigned long)shares[k])
        u -= (unsigned long)shares[k++];
    return k;
}

cdem_status cdem_sediment_deposit(cdem_sediment *sd, cdem_state *s, double sea_level, int32_t layer,
                                  int32_t born, long *added, cdem_error *err) {
    *added = 0;
    if (!sd->enabled || !sd->rng)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "sediment: deposit requested but surface.sedimentation is off");
    if (!isfinite(sea_level))
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "sediment: sea level = %g m: must be finite",
                         sea_level);
    const double rmax = sd->radius[CDEM_NUM_RADII - 1];
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        lo = fmin(lo, s->x[i] - s->radius[i]);
        hi = fmax(hi, s->x[i] + s->radius[i]);
    }
    if (!(hi > lo) || !isfinite(hi - lo))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "sediment: no free elements to deposit onto (span %g..%g m)", lo, hi);
    const double w = 2.0 * rmax;
    const double gx0 = lo - 2.0 * rmax; /* grid origin: one reach left of the span */
    const double span = (hi - lo + 4.0 * rmax) / w;
    if (!(span < 1e7))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "sediment: free elements span %g m = %g columns of %g m: too wide",
                         hi - lo, span, w);
    const size_t ncol = (size_t)span + 1;
    const cdem_grid cols = {.x0 = gx0, .y0 = 0.0, .cell = w, .nx = ncol, .ny = 1};
    const size_t n0 = s->n;
    if (ncol + 1 > sd->colcap) {
        const size_t c = ncol + 1 + ncol / 2 + 16;
        int32_t *a = realloc(sd->col_start, c * sizeof *a);
        if (a)
            sd->col_start = a;
        int32_t *b = a ? realloc(sd->col_head, c * sizeof *b) : NULL;
        if (!a || !b)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "sediment: out of memory (%zu columns)", c);
        sd->col_head = b;
        sd->colcap = c;
    }
    CDEM_TRY(grow_i32(&sd->col_items, &sd->itemcap, n0 + 1, err));
    CDEM_TRY(grow_i32(&sd->col_of, &sd->keycap, n0 + 1, err));
    /* CSR of the elements present (display-only footwall elements never touch anything) */
    for (size_t i = 0; i < n0; i++) {
        size_t c = 0;
        sd->col_of[i] =
            !(s->flags[i] & CDEM_FLAG_FOOTWALL) && cdem_grid_col_inside(&cols, s->x[i], &c)
                ? (int32_t)c
                : -1;
    }
    cdem_grid_sort(sd->col_of, n0, ncol, sd->col_start, sd->col_items);
    for (size_t c = 0; c < ncol; c++)
        sd->col_head[c] = -1;

    const long max_fail = 8 * (long)ncol + 64;
    const long max_attempts = 400 * (long)ncol + 4096;
    long fails = 0, count = 0;
    for (long attempt = 0; attempt < max_attempts && fails < max_fail; attempt++) {
        const int k = draw_class(sd->rng);
        const double r = sd->radius[k];
        const double u = gsl_rng_uniform(sd->rng);
        if (!(hi - lo > 2.0 * r)) {
            fails++;
            continue;
        }
        const double x = lo + r + u * (hi - lo - 2.0 * r);
        const double reach_max = r + rmax;
        size_t c0 = 1, c1 = 0; /* an empty range when the reach misses the grid */
        cdem_grid_col_range(&cols, x - reach_max, x + reach_max, &c0, &c1);
        double best = -INFINITY;
        for (size_t c = c0; c <= c1; c++) {
            for (int32_t a = sd->col_start[c]; a < sd->col_start[c + 1]; a++) {
                const int32_t j = sd->col_items[a];
                const double dx = s->x[j] - x, R = r + s->radius[j];
                if (fabs(dx) < R)
                    best = fmax(best, s->y[j] + sqrt(R * R - dx * dx));
            }
            for (int32_t q = sd->col_head[c]; q >= 0; q = sd->next_new[q]) {
                const size_t j = n0 + (size_t)q;
                const double dx = s->x[j] - x, R = r + s->radius[j];
                if (fabs(dx) < R)
                    best = fmax(best, s->y[j] + sqrt(R * R - dx * dx));
            }
        }
        if (!isfinite(best) || !(best < sea_level)) {
            fails++;
            continue;
        }
        fails = 0;
        size_t idx = 0;
        CDEM_TRY(cdem_state_append(s, -1, x, best, r, sd->mass[k], layer, CDEM_FLAG_GROWTH, born,
                                   &idx, err));
        const size_t q = idx - n0;
        CDEM_TRY(grow_i32(&sd->next_new, &sd->newcap, q + 1, err));
        const size_t c = cdem_grid_col(&cols, x);
        sd->next_new[q] = sd->col_head[c];
        sd->col_head[c] = (int32_t)q;
        count++;
    }
    *added = count;
    sd->n_deposited += count;
    return CDEM_OK;
}

cdem_status cdem_sediment_event(cdem_sediment *sd, cdem_integrator *it, cdem_state *s, long step,
                                int32_t born, long *added, cdem_error *err) {
    *added = 0;
    const double sea = cdem_sediment_sea_level(sd, step);
    const int32_t layer = (int32_t)(CDEM_PREGROWTH_LAYERS + 1 + sd->events);
    CDEM_TRY(cdem_sediment_deposit(sd, s, sea, layer, born, added, err));
    sd->events++;
    sd->event_step = step;
    sd->settle_end = step + sd->settling_steps;
    sd->settling_layer = layer;
    /* the list and forces of the new configuration (no tangential increment, no kick) */
    if (*added > 0)
        CDEM_TRY(cdem_integrator_prime(it, s, err));
    return CDEM_OK;
}

long cdem_sediment_make_cohesive(cdem_integrator *it, const cdem_state *s, int32_t layer) {
    const uint8_t flag =
        it->law.model == CDEM_MATERIAL_BONDED ? CDEM_PAIR_BONDED : CDEM_PAIR_COHESIVE;
    const cdem_neighbour *nb = &it->nb;
    long count = 0;
    for (size_t p = 0; p < nb->np; p++) {
        const int32_t i = nb->pi[p], j = nb->pj[p];
        const int mine = ((s->flags[i] & CDEM_FLAG_GROWTH) && s->layer[i] == layer) ||
                         ((s->flags[j] & CDEM_FLAG_GROWTH) && s->layer[j] == layer);
        if (mine && (nb->hist[p] & CDEM_PAIR_TOUCH) && nb->cls[p] != CDEM_CLASS_SLIP) {
            nb->hist[p] |= flag;
            count++;
        }
    }
    return count;
}

long cdem_sediment_after_step(cdem_sediment *sd, cdem_integrator *it, const cdem_state *s,
                              long step) {
    if (!sd->enabled || sd->settling_layer == 0 || step != sd->settle_end)
        return 0;
    const long made = cdem_sediment_make_cohesive(it, s, sd->settling_layer);
    sd->settling_layer = 0;
    return made;
}

/* ---------------------------------------------------------------- checkpoints */

cdem_status cdem_sediment_snapshot_put(const cdem_sediment *sd, cdem_snapshot *snap,
                                       cdem_error *err) {
    const char *P = "sed";
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "enabled", sd->enabled, err));
    if (!sd->enabled)
        return CDEM_OK;
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "ymax0", sd->ymax0, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "events", sd->events, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "event_step", sd->event_step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "settle_end", sd->settle_end, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "settling_layer", sd->settling_layer, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "n_deposited", sd->n_deposited, err));
    CDEM_TRY(cdem_ckpt_put_text(snap, P, "rng_type", gsl_rng_name(sd->rng), err));
    return cdem_ckpt_put_array(snap, P, "rng_state", CDEM_SNAP_U8, gsl_rng_size(sd->rng),
                               gsl_rng_state(sd->rng), err);
}

cdem_status cdem_sediment_snapshot_get(cdem_sediment *sd, const cdem_snapshot *snap,
                                       cdem_error *err) {
    const char *P = "sed";
    int64_t enabled = 0;
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "enabled", 0, 1, &enabled, err));
    if (enabled != sd->enabled)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "checkpoint sed.enabled = %lld but this run has surface.sedimentation = "
                         "%s: the checkpoint belongs to another model",
                         (long long)enabled, sd->enabled ? "on" : "off");
    if (!sd->enabled)
        return CDEM_OK;
    CDEM_TRY(
        cdem_ckpt_check_text(snap, P, "rng_type", gsl_rng_name(sd->rng), "random generator", err));
    const cdem_snapshot_array *st = NULL;
    CDEM_TRY(
        cdem_ckpt_get_array(snap, P, "rng_state", CDEM_SNAP_U8, gsl_rng_size(sd->rng), &st, err));
    int64_t events = 0, event_step = 0, settle_end = 0, layer = 0, n_dep = 0;
    double ymax0 = 0.0;
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "ymax0", &ymax0, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "events", 0, INT32_MAX, &events, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "event_step", -1, INT64_MAX, &event_step, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "settle_end", -1, INT64_MAX, &settle_end, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "settling_layer", 0, INT32_MAX, &layer, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "n_deposited", 0, INT64_MAX, &n_dep, err));
    memcpy(gsl_rng_state(sd->rng), st->data, st->count);
    sd->ymax0 = ymax0;
    sd->events = (int)events;
    sd->event_step = (long)event_step;
    sd->settle_end = (long)settle_end;
    sd->settling_layer = (int32_t)layer;
    sd->n_deposited = (long)n_dep;
    return CDEM_OK;
}
