/* bc_actors: the boundary of a run as a list of boundary actors (bc.h, "Boundaries compose";
 * docs/solver.md, "Boundaries on a timeline"): their set-up (each actor's parameters, model,
 * window and moving flag; the adopt pass), the front end the stepper and the run call (apply or the
 * split moves of the actors active in a step, the stop of a window that ended, gravity, net
 * displacement, views; with several actors, the zeroing of the velocities that the active actors
 * then add up) and their checkpoints (the first actor under "bc.", actor N under "bcN."). A run of
 * one actor without a window takes exactly the paths of before (`single`). The registry of
 * the modes and what the modes share are bc_registry.c. */
#include "bc.h"

#include "checkpoint.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
    a->m.composed = 1;
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
    const int n = cdem_params_actor_count(p);
    bc->m_first.composed = n > 1;
    cdem_status st = ops->init(bc->ctx, p, &bc->m_first, s, err);
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

/* The moving flags of the actors whose window holds deformation step k. */
static uint32_t active_flags(const cdem_bc *bc, long k) {
    uint32_t active = 0;
    for (int j = 0; j <= bc->n_more; j++) {
        const cdem_bc_ops *o;
        void *c;
        long ks, ke;
        uint32_t f;
        actor_of(bc, j, &o, &c, &ks, &ke, &f);
        if (in_window(ks, ke, k))
            active |= f;
    }
    return active;
}

/* Several actors: the velocity of the elements of the active ones (flags `active`) over lo..hi
 * is set to 0 before their moves, which add theirs (a block on two active blocks moves by
 * both). */
static void zero_active(cdem_state *s, uint32_t active, long lo, long hi) {
    for (long i = lo; i < hi; i++)
        if (s->flags[i] & active) {
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
    if (bc->n_more > 0)
        zero_active(s, active_flags(bc, k), 0, (long)s->n);
    if (in_window(bc->k_start, bc->k_stop, k))
        CDEM_TRY(apply_one(bc->ops, bc->ctx, bc->name, s, k - bc->k_start, du, dt, err));
    for (int j = 0; j < bc->n_more; j++) {
        cdem_bc_actor *a = &bc->more[j];
        if (in_window(a->k_start, a->k_stop, k))
            CDEM_TRY(apply_one(a->ops, a->ctx, a->name, s, k - a->k_start, du, dt, err));
    }
    return CDEM_OK;
}

/* The per-element moves of several actors (cdem_bc_step_move_of): the active actors'
 * velocities zeroed, then each active actor's moves over the range, in order (an element on
 * two active blocks takes both, velocities added). */
static void actors_step_move(const void *vbc, cdem_state *s, long lo, long hi) {
    const cdem_bc *bc = vbc;
    const long k = bc->k_now;
    if (bc->n_more > 0)
        zero_active(s, bc->active_now, lo, hi);
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
    bc->active_now = active_flags(bc, k);
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
