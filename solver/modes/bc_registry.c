/* bc_registry: the table from cdem_mode to the ops of its implementation, made from the rows
 * of common/modes.def (adding a mode is one new bc_<id>.c plus one row there), what is decided
 * from the parameters before the run (the rules and summary lines of every actor, the model's
 * mode part), and what several modes share: the wall geometry (cdem_bc_find_walls) and the
 * fault modes' summary lines. The run-time front end over the actors is bc_actors.c. */
#include "bc.h"

#include "summary_line.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const cdem_bc_ops *const *const registry[CDEM_MODE_COUNT] = {
#define CDEM_MODE(ID, id, word, clock, description) [CDEM_MODE_##ID] = &cdem_bc_##id,
#define CDEM_TEST_MODE                              CDEM_MODE
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

int cdem_bc_excludes(cdem_mode mode, const char *entry) {
    const cdem_bc_ops *ops = NULL;
    if (!entry || cdem_bc_find(mode, &ops, NULL) != CDEM_OK)
        return 0;
    for (size_t k = 0; ops->excludes && ops->excludes[k]; k++)
        if (strcmp(ops->excludes[k], entry) == 0)
            return 1;
    return 0;
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
            continue; /* CDEM_EXCLUDES_PROCESSES: the processes' own rules */
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

/* One fault of a run of several, for the geometry checks: its section, keys, trace (from the
 * base up to the assembly's top) and window in m of the run's boundary displacement. */
typedef struct {
    char section[20];
    const char *mode;
    int planar; /* 1: only its base moves (no fault elements along the trace) */
    char keys[1200];
    cdem_fault_polyline trace;
    double start, stop; /* m; stop: the run's end when the window has none */
} fault_of_run;

static double base_dip(const cdem_fault_polyline *t) {
    return atan2(t->y[1] - t->y[0], t->x[0] - t->x[1]);
}

/* Two faults of one run: they may not meet the base within the reach of the left one's ramp
 * below it (they would share the gap and its ramp), and their traces may not cross inside the
 * assembly when either lays fault elements along it (listric, irregular: the curves would cut
 * each other) or both act at once (the block between them would move two ways). */
static void fault_pair_rules(const fault_of_run *a, const fault_of_run *b, const cdem_model *m,
                             cdem_rule_log *log) {
    const fault_of_run *l = a->trace.x[0] <= b->trace.x[0] ? a : b, *r = l == a ? b : a;
    const double r_base = m->max_radius;
    const double reach = (l->stop - l->start + 4.0 * r_base) * cos(base_dip(&l->trace));
    const double gap = r->trace.x[0] - l->trace.x[0];
    if (gap <= reach + 2.0 * r_base) {
        cdem_rule_add(log,
                      "%s (%s; %s) and %s (%s; %s) overlap: they meet the base at x = %.6g m and "
                      "%.6g m, closer than the left one's ramp below the base reaches (%.6g m: "
                      "its displacement in its window plus 4 radii, along its basal dip): move "
                      "them apart (fault_location) or shorten the left one's window",
                      l->section, l->mode, l->keys, r->section, r->mode, r->keys, l->trace.x[0],
                      r->trace.x[0], reach + 2.0 * r_base);
        return;
    }
    const int together = a->start < b->stop && b->start < a->stop;
    if (l->planar && r->planar && !together)
        return; /* one after the other: the later fault cuts the earlier's zone */
    const double top = fmin(l->trace.y[l->trace.n - 1], r->trace.y[r->trace.n - 1]);
    const int steps = 400;
    for (int k = 1; k <= steps; k++) {
        const double y = top * (double)k / steps;
        const double xl = cdem_fault_file_x_at(&l->trace, y),
                     xr = cdem_fault_file_x_at(&r->trace, y);
        if (xr > xl)
            continue;
        cdem_rule_add(log,
                      "%s (%s; %s) and %s (%s; %s) cross inside the assembly: their traces meet "
                      "near x = %.6g m, y = %.6g m (its top is at %.6g m); %s: move them apart "
                      "(fault_location), change their dips%s",
                      l->section, l->mode, l->keys, r->section, r->mode, r->keys, xl, y, top,
                      l->planar && r->planar
                          ? "the wedge above the crossing would move two ways at once while "
                            "both act"
                          : "the fault elements along them would cut each other",
                      l->planar && r->planar ? " or give them windows one after the other "
                                               "(start, stop)"
                                             : "");
        return;
    }
}

/* The geometry checks of the faults of a run of several actors (fault_pair_rules). */
static void faults_rules(const cdem_params *p, int n, const cdem_model *m, cdem_rule_log *log) {
    fault_of_run f[CDEM_BOUNDARY_ACTORS];
    int nf = 0;
    const double run = (double)(m->total_steps - m->equil_steps) * m->displacement_per_step;
    for (int j = 0; j < n && j < CDEM_BOUNDARY_ACTORS; j++) {
        cdem_params pj;
        const cdem_bc_ops *ops = NULL;
        if (cdem_params_actor(p, j, &pj, NULL) != CDEM_OK ||
            cdem_bc_find(pj.mode, &ops, NULL) != CDEM_OK || !ops->trace)
            continue;
        fault_of_run *o = &f[nf];
        memset(o, 0, sizeof *o);
        if (ops->trace(&pj, m, m->height_m, &o->trace, NULL) != CDEM_OK || o->trace.n < 2)
            continue; /* the mode's own rules or its init name what is wrong */
        snprintf(o->section, sizeof o->section, j == 0 ? "[boundary]" : "[boundary.%d]", j + 1);
        o->mode = cdem_mode_name(pj.mode);
        o->planar = ops == cdem_bc_planar_fault;
        if (pj.mode == CDEM_MODE_IRREGULAR_FAULT)
            snprintf(o->keys, sizeof o->keys, "fault_location = %g, fault_file = %s",
                     pj.fault_location, pj.fault_file);
        else
            snprintf(o->keys, sizeof o->keys, "fault_location = %g, fault_dip = %g",
                     pj.fault_location, pj.fault_dip);
        o->start = pj.window_start;
        o->stop = pj.window_stop > 0.0 ? pj.window_stop : run;
        nf++;
    }
    for (int a = 0; a < nf; a++)
        for (int b = a + 1; b < nf; b++)
            fault_pair_rules(&f[a], &f[b], m, log);
    for (int a = 0; a < nf; a++)
        cdem_fault_file_free(&f[a].trace);
}

/* The modes that can be one of several actors, "a, b or c". */
static void composing_modes(char *words, size_t cap) {
    const char *w[CDEM_MODE_WORDS];
    size_t n = 0;
    for (int k = 0; k < CDEM_MODE_WORDS; k++)
        if ((*registry[k])->composes)
            w[n++] = cdem_mode_name((cdem_mode)k);
    cdem_words_or(w, n, words, cap);
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
    char can[160];
    composing_modes(can, sizeof can);
    if (cdem_bc_find(p->mode, &first, NULL) == CDEM_OK && !first->composes)
        cdem_rule_add(log,
                      "[boundary] mode = %s cannot be one of several boundary actors (%d are set: "
                      "[boundary.2] ...); modes that can: %s",
                      cdem_mode_name(p->mode), n, can);
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
                          "modes that can: %s",
                          j + 1, cdem_mode_name(pj.mode), can);
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
    if (have_model)
        faults_rules(p, n, &m, log);
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
    cdem_model m0 = *m; /* as the actor's init sees it (bc_actors.c) */
    m0.composed = cdem_params_actor_count(p) > 1;
    if (cdem_bc_find(p->mode, &ops, NULL) == CDEM_OK && ops->describe)
        ops->describe(p, &m0, out);
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
        mj.composed = 1;
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
