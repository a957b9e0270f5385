/* bc_registry: the table from cdem_mode to the ops of its implementation, made from the rows
 * of common/modes.def (adding a mode is one new bc_<id>.c plus one row there), the generic
 * front end that calls through the ops, and what several modes share: the wall geometry
 * (cdem_bc_find_walls) and the fault modes' summary lines. */
#include "bc.h"

#include "checkpoint.h"
#include "summary_line.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const cdem_bc_ops *const *const registry[CDEM_MODE_COUNT] = {
#define CDEM_MODE(ID, id, word) [CDEM_MODE_##ID] = &cdem_bc_##id,
#define CDEM_TEST_MODE          CDEM_MODE
#include "modes.def"
#undef CDEM_MODE
#undef CDEM_TEST_MODE
};

cdem_status cdem_bc_find(cdem_mode mode, const cdem_bc_ops **ops, cdem_error *err) {
    if ((int)mode < 0 || mode >= CDEM_MODE_COUNT) {
        char words[256]; /* the modes a parameter file can name */
        cdem_params_join_choices("boundary", "mode", words, sizeof words);
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "boundary.mode = %d: unknown mode; implemented modes: %s", (int)mode,
                         words);
    }
    *ops = *registry[mode];
    return CDEM_OK;
}

/* The rules of one actor's mode (p: the actor's parameters). */
static void mode_rules(const cdem_params *p, cdem_rule_log *log) {
    const cdem_bc_ops *ops = NULL;
    if (cdem_bc_find(p->mode, &ops, NULL) != CDEM_OK)
        return; /* the table's check names the value */
    const char *word = cdem_mode_name(p->mode);
    if (ops->validate)
        ops->validate(p, log);
    char v[64];
    for (size_t k = 0; ops->excludes && ops->excludes[k]; k++) {
        char section[32];
        const char *key = strchr(ops->excludes[k], '.');
        const size_t n = key ? (size_t)(key - ops->excludes[k]) : 0;
        if (!key || n >= sizeof section)
            continue;
        memcpy(section, ops->excludes[k], n);
        section[n] = '\0';
        const cdem_param_def *d = cdem_params_find(section, key + 1);
        if (!d)
            continue;
        if (d->type == CDEM_PTYPE_DOUBLE) {
            double x;
            memcpy(&x, (const char *)p + d->offset, sizeof x);
            if (!(x > 0))
                continue;
            cdem_params_format_number(x, v, sizeof v);
            cdem_rule_add(log,
                          "%s = %s %s cannot be used with mode = %s: set [%s] %s = 0 or choose "
                          "another mode",
                          d->key, v, d->unit, word, d->section, d->key);
        } else {
            int x;
            memcpy(&x, (const char *)p + d->offset, sizeof x);
            if (!x)
                continue;
            cdem_params_format_value(p, d, v, sizeof v);
            cdem_rule_add(log, "mode = %s excludes %s = %s: set [%s] %s = off", word, d->key, v,
                          d->section, d->key);
        }
    }
    if (p->inversion && !ops->inverts) {
        const char *inverting[CDEM_MODE_WORDS];
        size_t n = 0;
        for (int m = 0; m < CDEM_MODE_WORDS; m++)
            if ((*registry[m])->inverts)
                inverting[n++] = cdem_mode_name((cdem_mode)m);
        char words[256];
        cdem_words_or(inverting, n, words, sizeof words);
        cdem_rule_add(log,
                      "inversion = on needs mode = %s (got mode = %s): set [boundary] inversion = "
                      "off",
                      words, word);
    }
}

/* Adds the lines of `sub` to log, each after "[boundary.N]: ". */
static void add_prefixed(cdem_rule_log *log, const char *sub, int n) {
    for (const char *line = sub; *line;) {
        const char *eol = strchr(line, '\n');
        const int len = eol ? (int)(eol - line) : (int)strlen(line);
        if (len > 0)
            cdem_rule_add(log, "[boundary.%d]: %.*s", n, len, line);
        line = eol ? eol + 1 : line + len;
    }
}

/* A window's rules: in order, inside the run, on a mode whose boundaries move. */
static void window_rules(const cdem_params *pj, int j, const cdem_model *m, cdem_rule_log *log) {
    char sec[32];
    snprintf(sec, sizeof sec, j == 0 ? "boundary" : "boundary.%d", j + 1);
    if (!(pj->window_start > 0.0) && !(pj->window_stop > 0.0))
        return;
    const double run = (double)(m->total_steps - m->equil_steps) * m->displacement_per_step;
    if (m->mode.moving_boundaries == 0) {
        cdem_rule_add(log,
                      "[%s] start = %g m, stop = %g m: mode = %s moves no boundary, so it has no "
                      "window: set both to 0",
                      sec, pj->window_start, pj->window_stop, cdem_mode_name(pj->mode));
        return;
    }
    if (pj->window_stop > 0.0 && !(pj->window_stop > pj->window_start))
        cdem_rule_add(log, "[%s] stop = %g m must be after start = %g m (0: to the end of the run)",
                      sec, pj->window_stop, pj->window_start);
    if (pj->window_start >= run)
        cdem_rule_add(log,
                      "[%s] start = %g m is past the run's boundary displacement, %.6g m (time "
                      "runtime - equilibration at %.6g m/s): lower it or lengthen time.runtime",
                      sec, pj->window_start, run, m->boundary_speed);
    else if (pj->window_stop > run * (1.0 + 1e-12))
        cdem_rule_add(log,
                      "[%s] stop = %g m is past the run's boundary displacement, %.6g m (time "
                      "runtime - equilibration at %.6g m/s): lower it, set 0 (the end) or "
                      "lengthen time.runtime",
                      sec, pj->window_stop, run, m->boundary_speed);
}

void cdem_bc_rules(const cdem_params *p, cdem_rule_log *log) {
    const int n = cdem_params_actor_count(p);
    mode_rules(p, log);
    cdem_model m;
    const int have_model = cdem_bc_derive_model(p, &m, NULL) == CDEM_OK;
    if (have_model)
        window_rules(p, 0, &m, log);
    if (n == 1)
        return;
    const cdem_bc_ops *first = NULL;
    if (cdem_bc_find(p->mode, &first, NULL) == CDEM_OK && !first->composes)
        cdem_rule_add(log,
                      "[boundary] mode = %s cannot be one of several boundary actors (%d are set: "
                      "[boundary.2] ...); modes that can: planar-fault",
                      cdem_mode_name(p->mode), n);
    cdem_model_mode mode_first = cdem_model_mode_default();
    if (first && first->derive)
        first->derive(p, &mode_first);
    for (int j = 1; j < n; j++) {
        cdem_params pj;
        cdem_error e;
        if (cdem_params_actor(p, j, &pj, &e) != CDEM_OK) {
            cdem_rule_add(log, "[boundary.%d]: %s", j + 1, e.msg);
            continue;
        }
        char buf[CDEM_ERROR_MSG_MAX];
        cdem_rule_log sub = {buf, sizeof buf, 0, 0};
        buf[0] = '\0';
        mode_rules(&pj, &sub);
        add_prefixed(log, buf, j + 1);
        if (have_model)
            window_rules(&pj, j, &m, log);
        const cdem_bc_ops *ops = NULL;
        if (cdem_bc_find(pj.mode, &ops, NULL) != CDEM_OK)
            continue;
        if (!ops->composes)
            cdem_rule_add(log,
                          "[boundary.%d] mode = %s cannot be one of several boundary actors; "
                          "modes that can: planar-fault",
                          j + 1, cdem_mode_name(pj.mode));
        cdem_model_mode mj = cdem_model_mode_default();
        if (ops->derive)
            ops->derive(&pj, &mj);
        if (mj.gravity_off != mode_first.gravity_off ||
            mj.moving_boundaries != mode_first.moving_boundaries ||
            mj.base_spacing != mode_first.base_spacing ||
            mj.base_beyond_left != mode_first.base_beyond_left ||
            mj.base_beyond_right != mode_first.base_beyond_right ||
            mj.gravity_tilt != mode_first.gravity_tilt)
            cdem_rule_add(log,
                          "[boundary.%d] mode = %s asks for another model than [boundary] mode = "
                          "%s (gravity, moving boundaries or base): the actors share one model",
                          j + 1, cdem_mode_name(pj.mode), cdem_mode_name(p->mode));
    }
}

cdem_status cdem_bc_derive_model(const cdem_params *p, cdem_model *m, cdem_error *err) {
    if (!p)
        return cdem_model_derive(NULL, NULL, m, err); /* refuses it */
    const cdem_bc_ops *ops = NULL;
    CDEM_TRY(cdem_bc_find(p->mode, &ops, err));
    cdem_model_mode mode = cdem_model_mode_default();
    if (ops->derive)
        ops->derive(p, &mode);
    return cdem_model_derive(p, &mode, m, err);
}

/* The summary's line of a window, from the actor's parameters (nothing without one). */
static void describe_window(const cdem_params *pj, const cdem_model *m, FILE *out) {
    if (!(pj->window_start > 0.0) && !(pj->window_stop > 0.0))
        return;
    const double v = m->boundary_speed;
    if (pj->window_stop > 0.0)
        cdem_summary_line(out, "window",
                          "from %g m to %g m of the run's boundary displacement (%.6g s to %.6g s "
                          "after equilibration)",
                          pj->window_start, pj->window_stop, pj->window_start / v,
                          pj->window_stop / v);
    else
        cdem_summary_line(out, "window",
                          "from %g m of the run's boundary displacement (%.6g s after "
                          "equilibration) to the end",
                          pj->window_start, pj->window_start / v);
}

void cdem_bc_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    const cdem_bc_ops *ops = NULL;
    if (cdem_bc_find(p->mode, &ops, NULL) == CDEM_OK && ops->describe)
        ops->describe(p, m, out);
    describe_window(p, m, out);
    for (int j = 1; j < cdem_params_actor_count(p); j++) {
        cdem_params pj;
        if (cdem_params_actor(p, j, &pj, NULL) != CDEM_OK)
            continue;
        char label[48];
        snprintf(label, sizeof label, "actor %d ([boundary.%d])", j + 1, j + 1);
        cdem_summary_line(out, label, "mode %s", cdem_mode_name(pj.mode));
        describe_window(&pj, m, out);
        cdem_model mj;
        long ks, ke;
        cdem_bc_actor_model(&pj, j, m, &mj, &ks, &ke);
        if (cdem_bc_find(pj.mode, &ops, NULL) == CDEM_OK && ops->describe)
            ops->describe(&pj, &mj, out);
    }
}

static const char *sense_word(cdem_fault_sense s) {
    return s == CDEM_SENSE_REVERSE ? "reverse" : "normal";
}

static const char *other_sense_word(cdem_fault_sense s) {
    return s == CDEM_SENSE_REVERSE ? "normal" : "reverse";
}

void cdem_bc_describe_fault(const cdem_params *p, const cdem_model *m, FILE *out) {
    cdem_summary_line(out, "sense", "%s", sense_word(p->fault_sense));
    cdem_summary_line(out, "fault location", "%g of the base = %.6g m from the left end",
                      p->fault_location, p->fault_location * m->width_m);
}

void cdem_bc_describe_inversion(const cdem_params *p, const cdem_model *m, FILE *out) {
    if (!p->inversion) {
        cdem_summary_line(out, "inversion", "off");
        return;
    }
    /* The mode's step counter turns at inversion_percent of the deformation steps; it does
     * not advance while a deposit settles, so with sedimentation the slip is what the
     * steps left after the settling give (docs/solver.md, section 8). */
    long def_steps = m->total_steps - m->equil_steps;
    long deposits = cdem_model_sediment_events(p, m);
    long moving = def_steps - deposits * m->settling_steps;
    long turn = cdem_model_inversion_step(p, m);
    double before = (double)(turn < moving ? turn : moving) * m->displacement_per_step;
    double after = (double)(moving > turn ? moving - turn : 0) * m->displacement_per_step;
    double net = before - after;
    if (deposits > 0)
        cdem_summary_line(out, "inversion",
                          "at %g %% of the deformation steps: %.4g m %s, then %.4g m %s "
                          "(%ld deposits settle, %ld steps each, with the boundaries still)",
                          p->inversion_percent, before, sense_word(p->fault_sense), after,
                          other_sense_word(p->fault_sense), deposits, m->settling_steps);
    else
        cdem_summary_line(out, "inversion",
                          "at %g %% of the displacement: %.4g m %s, then %.4g m %s",
                          p->inversion_percent, before, sense_word(p->fault_sense), after,
                          other_sense_word(p->fault_sense));
    if (fabs(net) <= 1.5 * m->displacement_per_step) /* the turn is a whole step */
        cdem_summary_line(out, "net displacement",
                          "0 m (the block returns to its starting position, within a step)");
    else
        cdem_summary_line(out, "net displacement", "%.4g m %s", fabs(net),
                          net > 0 ? sense_word(p->fault_sense) : other_sense_word(p->fault_sense));
}

/* Deformation steps of d metres of the run's boundary displacement. */
static long steps_of(double d, const cdem_model *m) {
    return d > 0.0 ? (long)llround(d / m->displacement_per_step) : 0;
}

void cdem_bc_actor_model(const cdem_params *pj, int j, const cdem_model *run_model, cdem_model *out,
                         long *k_start, long *k_stop) {
    *out = *run_model;
    out->moving_flag = j == 0 ? (uint32_t)CDEM_FLAG_MOVING : CDEM_FLAG_ACTOR_MOVING(j + 1);
    *k_start = steps_of(pj->window_start, run_model);
    /* a stop inside the first step still stops (0 means none) */
    *k_stop =
        pj->window_stop > 0.0
            ? (steps_of(pj->window_stop, run_model) > 0 ? steps_of(pj->window_stop, run_model) : 1)
            : 0;
    if (*k_start == 0 && *k_stop == 0)
        return; /* no window: the run's model as it is */
    const long run = run_model->total_steps - run_model->equil_steps;
    const long last = *k_stop > 0 && *k_stop < run ? *k_stop : run;
    const long window = last > *k_start ? last - *k_start : 0;
    out->total_steps = run_model->equil_steps + window;
    out->total_displacement =
        run > 0 ? run_model->total_displacement * (double)window / (double)run : 0.0;
}

/* 1 when the window (k_start, k_stop] holds deformation step k (>= 1); k_stop 0: no stop (a
 * cdem_bc of zeros, as the tests make by hand, is one actor without a window). */
static int in_window(long k_start, long k_stop, long k) {
    return k > k_start && (k_stop == 0 || k <= k_stop);
}

static void free_actor(cdem_bc_actor *a) {
    if (a->ops && a->ops->free && a->ctx)
        a->ops->free(a->ctx);
    free(a->ctx);
    free(a->p);
    memset(a, 0, sizeof *a);
}

/* Makes actor j (>= 1) of p: its parameters, model, window, context and init on s. */
static cdem_status init_actor(cdem_bc_actor *a, const cdem_params *p, int j, const cdem_model *m,
                              cdem_state *s, cdem_error *err) {
    memset(a, 0, sizeof *a);
    a->p = malloc(sizeof *a->p);
    if (!a->p)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for boundary actor %d", j + 1);
    CDEM_TRY(cdem_params_actor(p, j, a->p, err));
    CDEM_TRY(cdem_bc_find(a->p->mode, &a->ops, err));
    a->name = cdem_mode_name(a->p->mode);
    if (!a->ops->composes)
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "[boundary.%d] mode = %s cannot be one of several boundary actors", j + 1,
                         a->name);
    cdem_bc_actor_model(a->p, j, m, &a->m, &a->k_start, &a->k_stop);
    a->ctx = calloc(1, a->ops->state_size);
    if (!a->ctx)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for boundary actor %d (%s)", j + 1,
                         a->name);
    cdem_status st = a->ops->init(a->ctx, a->p, &a->m, s, err);
    if (st != CDEM_OK)
        cdem_error_prefix(err, "[boundary.%d]", j + 1);
    return st;
}

/* The window (k_start, k_stop], moving flag and ops of actor j (0: the first). */
static void actor_of(const cdem_bc *bc, int j, const cdem_bc_ops **ops, void **ctx, long *k_start,
                     long *k_stop, uint32_t *moving) {
    if (j == 0) {
        *ops = bc->ops;
        *ctx = bc->ctx;
        *k_start = bc->k_start;
        *k_stop = bc->k_stop;
        *moving = CDEM_FLAG_MOVING;
        return;
    }
    const cdem_bc_actor *a = &bc->more[j - 1];
    *ops = a->ops;
    *ctx = a->ctx;
    *k_start = a->k_start;
    *k_stop = a->k_stop;
    *moving = a->m.moving_flag;
}

/* Two actors whose windows overlap may not move one element both. */
static cdem_status check_shared(const cdem_bc *bc, const cdem_state *s, cdem_error *err) {
    for (int i = 0; i <= bc->n_more; i++)
        for (int j = i + 1; j <= bc->n_more; j++) {
            const cdem_bc_ops *o;
            void *c;
            long si, ei, sj, ej;
            uint32_t fi, fj;
            actor_of(bc, i, &o, &c, &si, &ei, &fi);
            actor_of(bc, j, &o, &c, &sj, &ej, &fj);
            const long end_i = ei ? ei : LONG_MAX, end_j = ej ? ej : LONG_MAX;
            if (!(si < end_j && sj < end_i))
                continue; /* one after the other */
            for (size_t e = 0; e < s->n; e++)
                if ((s->flags[e] & fi) && (s->flags[e] & fj)) {
                    char a[32], b[32];
                    snprintf(a, sizeof a, i == 0 ? "[boundary]" : "[boundary.%d]", i + 1);
                    snprintf(b, sizeof b, "[boundary.%d]", j + 1);
                    return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                                     "boundary actors %s and %s act at the same time and would "
                                     "both move boundary element id %d (at x = %.6g m, y = %.6g "
                                     "m): one block cannot move two ways at once; give them "
                                     "windows one after the other (start, stop)",
                                     a, b, (int)s->id[e], s->x[e], s->y[e]);
                }
        }
    return CDEM_OK;
}

cdem_status cdem_bc_init(cdem_bc *bc, const cdem_params *p, const cdem_model *m, cdem_state *s,
                         cdem_error *err) {
    memset(bc, 0, sizeof *bc);
    const cdem_bc_ops *ops = NULL;
    CDEM_TRY(cdem_bc_find(p->mode, &ops, err));
    bc->ctx = calloc(1, ops->state_size);
    if (!bc->ctx)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the %s boundary mode",
                         cdem_mode_name(p->mode));
    bc->ops = ops;
    bc->name = cdem_mode_name(p->mode);
    bc->lateral_pressure = ops->confined ? p->confining_pressure : 0.0;
    cdem_bc_actor_model(p, 0, m, &bc->m_first, &bc->k_start, &bc->k_stop);
    cdem_status st = ops->init(bc->ctx, p, &bc->m_first, s, err);
    const int n = cdem_params_actor_count(p);
    if (st == CDEM_OK && n > 1) {
        bc->more = calloc((size_t)(n - 1), sizeof *bc->more);
        if (!bc->more)
            st = CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for %d boundary actors", n);
        for (int j = 1; st == CDEM_OK && j < n; j++) {
            bc->n_more = j;
            st = init_actor(&bc->more[j - 1], p, j, m, s, err);
        }
        if (st == CDEM_OK && !ops->composes)
            st = CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                           "[boundary] mode = %s cannot be one of several boundary actors",
                           bc->name);
        /* every actor's elements exist now: each takes those that ride on its block */
        if (st == CDEM_OK && ops->adopt)
            ops->adopt(bc->ctx, s);
        for (int j = 0; st == CDEM_OK && j < bc->n_more; j++)
            if (bc->more[j].ops->adopt)
                bc->more[j].ops->adopt(bc->more[j].ctx, s);
        if (st == CDEM_OK)
            st = check_shared(bc, s, err);
    }
    if (st != CDEM_OK) {
        cdem_bc_free(bc);
        return st;
    }
    return CDEM_OK;
}

/* Sets the velocity of the elements of the actors whose window ended with step k - 1 to 0:
 * the walls they moved stand still from step k on (another actor may move them again). */
static void stop_ended(const cdem_bc *bc, cdem_state *s, long k) {
    uint32_t ended = 0;
    for (int j = 0; j <= bc->n_more; j++) {
        const cdem_bc_ops *o;
        void *c;
        long ks, ke;
        uint32_t f;
        actor_of(bc, j, &o, &c, &ks, &ke, &f);
        if (ke != 0 && k == ke + 1)
            ended |= f;
    }
    if (!ended)
        return;
    for (size_t i = 0; i < s->n; i++)
        if (s->flags[i] & ended) {
            s->vx[i] = 0.0;
            s->vy[i] = 0.0;
        }
}

/* apply of one actor at the run's deformation step k (k <= 0: an equilibration step). */
static cdem_status apply_one(const cdem_bc_ops *ops, void *ctx, const char *name, cdem_state *s,
                             long k, double du, double dt, cdem_error *err) {
    if (ops->step_begin && ops->step_move) {
        CDEM_TRY(ops->step_begin(ctx, k, du, dt, err));
        ops->step_move(ctx, s, 0, (long)s->n);
        return CDEM_OK;
    }
    if (!ops->apply)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_apply: mode %s has neither apply nor step_begin and step_move",
                         name);
    return ops->apply(ctx, s, k, du, dt, err);
}

cdem_status cdem_bc_apply(cdem_bc *bc, cdem_state *s, long k, double du, double dt,
                          cdem_error *err) {
    if (!bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_bc_apply: boundary mode not initialised");
    if (k <= 0) /* equilibration: the first actor, when it moves then */
        return bc->ops->moves_in_equilibration
                   ? apply_one(bc->ops, bc->ctx, bc->name, s, 0, du, dt, err)
                   : CDEM_OK;
    bc->k_now = k;
    stop_ended(bc, s, k);
    if (in_window(bc->k_start, bc->k_stop, k))
        CDEM_TRY(apply_one(bc->ops, bc->ctx, bc->name, s, k - bc->k_start, du, dt, err));
    for (int j = 0; j < bc->n_more; j++) {
        cdem_bc_actor *a = &bc->more[j];
        if (in_window(a->k_start, a->k_stop, k))
            CDEM_TRY(apply_one(a->ops, a->ctx, a->name, s, k - a->k_start, du, dt, err));
    }
    return CDEM_OK;
}

/* The per-element moves of several actors (cdem_bc_step_move_of): each active actor's over
 * the range, in order (no element moves with two: check_shared). */
static void actors_step_move(const void *vbc, cdem_state *s, long lo, long hi) {
    const cdem_bc *bc = vbc;
    const long k = bc->k_now;
    if (in_window(bc->k_start, bc->k_stop, k))
        bc->ops->step_move(bc->ctx, s, lo, hi);
    for (int j = 0; j < bc->n_more; j++) {
        const cdem_bc_actor *a = &bc->more[j];
        if (in_window(a->k_start, a->k_stop, k))
            a->ops->step_move(a->ctx, s, lo, hi);
    }
}

/* 1 when an actor's window ended with step k - 1 (its elements stop in step k: stop_ended). */
static int window_ends(const cdem_bc *bc, long k) {
    if (bc->k_stop != 0 && k == bc->k_stop + 1)
        return 1;
    for (int j = 0; j < bc->n_more; j++)
        if (bc->more[j].k_stop != 0 && k == bc->more[j].k_stop + 1)
            return 1;
    return 0;
}

/* 1 when every actor active at step k (>= 1) is split for the stepper (step_begin, step_move,
 * boundary_only) and no window ends (stop_ended runs in cdem_bc_apply, which the stepper
 * then calls before its pass: it touches boundary elements only). */
static int all_split(const cdem_bc *bc, long k) {
    if (window_ends(bc, k))
        return 0;
    if (in_window(bc->k_start, bc->k_stop, k) &&
        !(bc->ops->step_begin && bc->ops->step_move && bc->ops->boundary_only))
        return 0;
    for (int j = 0; j < bc->n_more; j++) {
        const cdem_bc_ops *o = bc->more[j].ops;
        if (in_window(bc->more[j].k_start, bc->more[j].k_stop, k) &&
            !(o->step_begin && o->step_move && o->boundary_only))
            return 0;
    }
    return 1;
}

/* 1 when the first actor alone, without a window, makes the boundary: the paths of a run
 * before actors existed. */
static int single(const cdem_bc *bc) {
    return bc->n_more == 0 && bc->k_start == 0 && bc->k_stop == 0;
}

cdem_bc_move_fn cdem_bc_step_move_of(const cdem_bc *bc, long k) {
    if (!bc || !bc->ops)
        return NULL;
    if (k <= 0 || single(bc)) {
        if (!bc->ops->step_begin || !bc->ops->boundary_only)
            return NULL;
        if (k <= 0 && !bc->ops->moves_in_equilibration)
            return NULL; /* nothing moves in this step */
        return bc->ops->step_move;
    }
    return all_split(bc, k) ? actors_step_move : NULL;
}

const void *cdem_bc_step_move_ctx(const cdem_bc *bc) {
    return single(bc) ? bc->ctx : (const void *)bc;
}

cdem_status cdem_bc_step_begin(cdem_bc *bc, long k, double du, double dt, cdem_error *err) {
    if (!bc || !bc->ops || (single(bc) && !bc->ops->step_begin))
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_bc_step_begin: the mode has no step_begin");
    if (k <= 0 || single(bc))
        return bc->ops->step_begin(bc->ctx, k <= 0 ? 0 : k, du, dt, err);
    bc->k_now = k;
    if (in_window(bc->k_start, bc->k_stop, k))
        CDEM_TRY(bc->ops->step_begin(bc->ctx, k - bc->k_start, du, dt, err));
    for (int j = 0; j < bc->n_more; j++) {
        cdem_bc_actor *a = &bc->more[j];
        if (in_window(a->k_start, a->k_stop, k))
            CDEM_TRY(a->ops->step_begin(a->ctx, k - a->k_start, du, dt, err));
    }
    return CDEM_OK;
}

int cdem_bc_apply_is_boundary_only(const cdem_bc *bc, long k) {
    if (!bc || !bc->ops)
        return 0;
    if (k <= 0)
        return bc->ops->boundary_only || !bc->ops->moves_in_equilibration;
    if (single(bc))
        return bc->ops->boundary_only;
    if (in_window(bc->k_start, bc->k_stop, k) && !bc->ops->boundary_only)
        return 0;
    for (int j = 0; j < bc->n_more; j++)
        if (in_window(bc->more[j].k_start, bc->more[j].k_stop, k) &&
            !bc->more[j].ops->boundary_only)
            return 0;
    return 1;
}

int cdem_bc_gravity(const cdem_bc *bc, long k, double g, double *gx, double *gy) {
    if (!bc || !bc->ops || k < 1)
        return 0;
    if (bc->ops->gravity && in_window(bc->k_start, bc->k_stop, k)) {
        bc->ops->gravity(bc->ctx, k - bc->k_start, g, gx, gy);
        return 1;
    }
    for (int j = 0; j < bc->n_more; j++) {
        const cdem_bc_actor *a = &bc->more[j];
        if (a->ops->gravity && in_window(a->k_start, a->k_stop, k)) {
            a->ops->gravity(a->ctx, k - a->k_start, g, gx, gy);
            return 1;
        }
    }
    return 0;
}

int cdem_bc_moves_in_equilibration(const cdem_bc *bc) {
    return bc && bc->ops && bc->ops->moves_in_equilibration;
}

double cdem_bc_net_displacement(const cdem_bc *bc) {
    if (!bc || !bc->ops)
        return 0.0;
    double net = bc->ops->net_displacement(bc->ctx);
    for (int j = 0; j < bc->n_more; j++)
        net += bc->more[j].ops->net_displacement(bc->more[j].ctx);
    return net;
}

cdem_status cdem_bc_begin_deformation(cdem_bc *bc, const cdem_state *s, unsigned char *keep,
                                      size_t *n_remove, cdem_error *err) {
    *n_remove = 0;
    if (!bc || !bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_begin_deformation: boundary mode not initialised");
    if (bc->ops->begin_deformation)
        CDEM_TRY(bc->ops->begin_deformation(bc->ctx, s, keep, n_remove, err));
    for (int j = 0; j < bc->n_more; j++)
        if (bc->more[j].ops->begin_deformation) {
            size_t more = 0;
            CDEM_TRY(bc->more[j].ops->begin_deformation(bc->more[j].ctx, s, keep, &more, err));
            *n_remove += more;
        }
    return CDEM_OK;
}

/* "from X m to Y m" of a window (k_start, k_stop] of steps of du metres. */
static void window_text(long k_start, long k_stop, double du, char *buf, size_t cap) {
    if (k_stop == 0)
        snprintf(buf, cap, "from %.6g m of the run's boundary displacement to the end",
                 (double)k_start * du);
    else
        snprintf(buf, cap, "from %.6g m to %.6g m of the run's boundary displacement",
                 (double)k_start * du, (double)k_stop * du);
}

void cdem_bc_view(const cdem_bc *bc, FILE *out) {
    if (!bc || !bc->ops)
        return;
    bc->ops->view(bc->ctx, out);
    char w[160];
    if (!single(bc)) {
        window_text(bc->k_start, bc->k_stop, bc->m_first.displacement_per_step, w, sizeof w);
        fprintf(out, "Boundary actor 1 ([boundary]): %s.\n", w);
    }
    for (int j = 0; j < bc->n_more; j++) {
        const cdem_bc_actor *a = &bc->more[j];
        window_text(a->k_start, a->k_stop, a->m.displacement_per_step, w, sizeof w);
        fprintf(out, "Boundary actor %d ([boundary.%d]): %s. ", j + 2, j + 2, w);
        a->ops->view(a->ctx, out);
    }
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
    for (int j = 0; j < bc->n_more; j++)
        free_actor(&bc->more[j]);
    free(bc->more);
    memset(bc, 0, sizeof *bc);
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

/* Copies the arrays of `from` whose names start with prefix_from (e.g. "bc.") into `to`,
 * renamed to start with prefix_to. */
static cdem_status copy_renamed(const cdem_snapshot *from, const char *prefix_from,
                                cdem_snapshot *to, const char *prefix_to, cdem_error *err) {
    const size_t lf = strlen(prefix_from);
    for (size_t i = 0; i < cdem_snapshot_count(from); i++) {
        const cdem_snapshot_array *a = cdem_snapshot_at(from, i);
        if (strncmp(a->name, prefix_from, lf) != 0)
            continue;
        char name[CDEM_SNAPSHOT_NAME_MAX];
        if ((size_t)snprintf(name, sizeof name, "%s%s", prefix_to, a->name + lf) >= sizeof name)
            return CDEM_FAIL(err, CDEM_ERR_INVALID, "checkpoint name %s%s is too long", prefix_to,
                             a->name + lf);
        CDEM_TRY(cdem_snapshot_put(to, name, a->type, a->count, a->data, err));
    }
    return CDEM_OK;
}

/* The first actor under "bc." (as before actors existed), actor N under "bcN.": each mode
 * saves under "bc.", and its arrays are renamed on the way. */
static cdem_status put_one(const cdem_bc_ops *ops, const void *ctx, const char *name,
                           cdem_snapshot *snap, cdem_error *err) {
    if (!ops->save)
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "boundary mode %s cannot write checkpoints in this build (set "
                         "output.checkpoint_interval = 0)",
                         name);
    CDEM_TRY(cdem_ckpt_put_text(snap, "bc", "mode", name, err));
    return ops->save(ctx, snap, err);
}

static cdem_status get_one(const cdem_bc_ops *ops, void *ctx, const char *name,
                           const cdem_snapshot *snap, cdem_error *err) {
    if (!ops->restore)
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "boundary mode %s cannot resume from a checkpoint in this build", name);
    CDEM_TRY(cdem_ckpt_check_text(snap, "bc", "mode", name, "boundary mode", err));
    return ops->restore(ctx, snap, err);
}

cdem_status cdem_bc_snapshot_put(const cdem_bc *bc, cdem_snapshot *snap, cdem_error *err) {
    if (!bc || !bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_snapshot_put: boundary mode not initialised");
    CDEM_TRY(put_one(bc->ops, bc->ctx, bc->name, snap, err));
    if (bc->n_more == 0)
        return CDEM_OK;
    cdem_snapshot *one = NULL;
    CDEM_TRY(cdem_snapshot_alloc(&one, err));
    cdem_status st = CDEM_OK;
    for (int j = 0; st == CDEM_OK && j < bc->n_more; j++) {
        char prefix[16];
        snprintf(prefix, sizeof prefix, "bc%d.", j + 2);
        cdem_snapshot_clear(one);
        st = put_one(bc->more[j].ops, bc->more[j].ctx, bc->more[j].name, one, err);
        if (st == CDEM_OK)
            st = copy_renamed(one, "bc.", snap, prefix, err);
    }
    cdem_snapshot_free(one);
    return st;
}

cdem_status cdem_bc_snapshot_get(cdem_bc *bc, const cdem_snapshot *snap, cdem_error *err) {
    if (!bc || !bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_snapshot_get: boundary mode not initialised");
    CDEM_TRY(get_one(bc->ops, bc->ctx, bc->name, snap, err));
    if (bc->n_more == 0)
        return CDEM_OK;
    cdem_snapshot *one = NULL;
    CDEM_TRY(cdem_snapshot_alloc(&one, err));
    cdem_status st = CDEM_OK;
    for (int j = 0; st == CDEM_OK && j < bc->n_more; j++) {
        char prefix[16];
        snprintf(prefix, sizeof prefix, "bc%d.", j + 2);
        cdem_snapshot_clear(one);
        st = copy_renamed(snap, prefix, one, "bc.", err);
        if (st == CDEM_OK)
            st = get_one(bc->more[j].ops, bc->more[j].ctx, bc->more[j].name, one, err);
        if (st != CDEM_OK)
            cdem_error_prefix(err, "boundary actor %d ([boundary.%d])", j + 2, j + 2);
    }
    cdem_snapshot_free(one);
    return st;
}
