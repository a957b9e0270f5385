/* bc_registry: the table from cdem_mode to the ops of its implementation, made from the rows
 * of common/modes.def (adding a mode is one new bc_<id>.c plus one row there), the generic
 * front end that calls through the ops, and what several modes share: the wall geometry
 * (cdem_bc_find_walls) and the fault modes' summary lines. */
#include "bc.h"

#include "checkpoint.h"
#include "summary_line.h"

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

void cdem_bc_rules(const cdem_params *p, cdem_rule_log *log) {
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

void cdem_bc_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    const cdem_bc_ops *ops = NULL;
    if (cdem_bc_find(p->mode, &ops, NULL) == CDEM_OK && ops->describe)
        ops->describe(p, m, out);
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
                         bc->name);
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

int cdem_bc_gravity(const cdem_bc *bc, long k, double g, double *gx, double *gy) {
    if (!bc || !bc->ops || !bc->ops->gravity || k < 1)
        return 0;
    bc->ops->gravity(bc->ctx, k, g, gx, gy);
    return 1;
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
    bc->name = NULL;
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
                         bc->name);
    CDEM_TRY(cdem_ckpt_put_text(snap, "bc", "mode", bc->name, err));
    return bc->ops->save(bc->ctx, snap, err);
}

cdem_status cdem_bc_snapshot_get(cdem_bc *bc, const cdem_snapshot *snap, cdem_error *err) {
    if (!bc || !bc->ops)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_bc_snapshot_get: boundary mode not initialised");
    if (!bc->ops->restore)
        return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED,
                         "boundary mode %s cannot resume from a checkpoint in this build",
                         bc->name);
    CDEM_TRY(cdem_ckpt_check_text(snap, "bc", "mode", bc->name, "boundary mode", err));
    return bc->ops->restore(bc->ctx, snap, err);
}
