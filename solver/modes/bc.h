/* bc: boundary (faulting) modes. A mode is one file solver/modes/bc_<name>.c defining one
 * static const cdem_bc_ops and one exported pointer cdem_bc_<id>, and one row of
 * common/modes.def (its enum value and word); the registry (bc_registry.c) is made from the
 * rows, so the solver never switches on mode names and nothing else names a mode. Checklist
 * for a mode (bc_planar_fault.c is the template):
 *   required: state_size (bytes of the private context, calloc'd by cdem_bc_init); init
 *   (after the assembly is built: add/flag the mode's boundary elements CDEM_FLAG_WALL /
 *   FAULT / MOVING, record its geometry); apply (deformation step k, 1-based: move the
 *   prescribed elements by this step's boundary increment du, sense decided by the mode, and
 *   set their velocity to the boundary velocity; walls never move otherwise; a mode with
 *   moves_in_equilibration = 1 is also called on every equilibration step, with k = 0; a
 *   boundary_only mode gives it as step_begin + step_move instead, so that the stepper can
 *   thread the moves: bc_planar_fault.c does); net_displacement (m, of the moving boundary
 *   so far); view (one paragraph of the effective settings of the set-up mode);
 *   before the run, from the parameters alone (all optional): validate (its parameter rules),
 *   excludes (switches it cannot run with), inverts (boundary.inversion allowed), derive (its
 *   part of the model: gravity off, moving boundaries and display unit, base spacing, an
 *   input file), describe (its lines of the summary);
 *   optional during the run: free (NULL: the context owns no memory); begin_deformation (once
 *   before deformation step 1, may clear keep[i] of elements to remove, e.g. repose drops its
 *   walls; the solver removes them through the escape path, histories of the rest kept);
 *   confined (the solver loads the free side edges with boundary.confining_pressure);
 *   measure; save/restore (checkpoints).
 *
 * Boundaries compose (docs/solver.md, "Boundaries on a timeline"). A run holds a list of
 * boundary actors: [boundary] is the first, [boundary.2] ... [boundary.8] (params.h,
 * cdem_params_actor) add more, each a mode instance with its own parameters and its own window
 * of the run's deformation steps (start, stop: metres of the run's boundary displacement),
 * stepped in order. An actor's mode sees deformation steps counted from its window's start,
 * and a model whose deformation is its window (cdem_bc_actor_model): its inversion and its
 * ramps are its window's. Each actor's elements carry its own moving flag (the model's
 * moving_flag, cdem_bc_moving_flag), so that actors never take each other's elements; a mode
 * that can be one of several sets `composes` and `adopt` (the other actors' elements that
 * ride on its block). Windows may overlap: the actors whose windows hold a step move in turn,
 * and an element that rides on several active blocks (a block in the hanging wall of two
 * faults) takes the sum of their moves: the front end zeroes the velocity of every element of
 * an active actor, and a composing mode, told by its model (m->composed), adds its move's
 * velocity instead of setting it. When an actor's window ends its elements stop (their
 * velocity is set to 0). The faults' geometry is checked before the run (their traces, the
 * `trace` hook): faults that meet the base too close together or whose traces cross inside
 * the assembly are refused, naming both sections. A run of one actor without a window goes
 * through exactly the code paths of a run before actors existed (the refactor guard,
 * scripts/refactor_guard.sh).
 * Ownership: cdem_bc owns its contexts. Thread safety: one cdem_bc per run. Units: m, s. */
#ifndef CDEM_BC_H
#define CDEM_BC_H

#include "cdem_error.h"
#include "fault_file.h"
#include "model.h"
#include "params.h"
#include "snapshot.h"
#include "state.h"

#include <stdio.h>

typedef struct {
    size_t state_size; /* bytes of the private context, > 0 */
    cdem_status (*init)(void *ctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                        cdem_error *err);
    cdem_status (*apply)(void *ctx, cdem_state *s, long k, double du, double dt, cdem_error *err);
    /* 1: the mode also moves boundaries during equilibration: apply is then called on every
     * equilibration step with k = 0, after the drift, with s->fx/fy of the boundary elements
     * holding their contact forces of the previous step (biaxial servo platens); 0: apply
     * sees only deformation steps (k >= 1) */
    int moves_in_equilibration;
    /* 1: apply reads and writes only boundary elements (CDEM_FLAGS_BOUNDARY) and the context,
     * never a free element, so it commutes exactly with the drift of the free elements: the
     * stepper then applies it first and drifts inside the force pass's parallel region (one
     * region a step instead of two). 0 (the safe default for a new mode): apply runs after
     * the drift, as documented above (biaxial: its servo reads the free elements' extent). */
    int boundary_only;
    /* optional, for a boundary_only mode (both NULL: apply does it all): apply split in two,
     * so that the stepper moves the elements inside its parallel region, each thread over
     * its own range. step_begin does the step's once-only work (checks, sense and velocities
     * kept in the context, net displacement); step_move the per-element work over elements
     * lo..hi-1, reading the context only. Such a mode has no apply: cdem_bc_apply is
     * step_begin, then step_move over every element. */
    cdem_status (*step_begin)(void *ctx, long k, double du, double dt, cdem_error *err);
    void (*step_move)(const void *ctx, cdem_state *s, long lo, long hi);
    double (*net_displacement)(const void *ctx);
    void (*view)(const void *ctx, FILE *out);
    void (*free)(void *ctx); /* may be NULL when the context owns no memory */
    /* may be NULL; keep has s->n entries, all 1 on entry; *n_remove = number cleared */
    cdem_status (*begin_deformation)(void *ctx, const cdem_state *s, unsigned char *keep,
                                     size_t *n_remove, cdem_error *err);
    /* 1: the solver applies boundary.confining_pressure (N/m, ramped over equilibration:
     * cdem_bc_confining_ramp) to the free left/right edge elements (biaxial); 0: no lateral
     * load */
    int confined;
    /* may be NULL (both 0): sample = 1 at every time-series sample, after the step's boundary
     * forces are summed (the mode may record them); sample = 0 for an increment (current
     * values from what was recorded, forces not read); step = completed time steps */
    void (*measure)(void *ctx, const cdem_state *s, long step, int sample, double *axial_strain,
                    double *differential_stress);
    /* checkpoints (may be NULL: the mode cannot be checkpointed, CDEM_ERR_UNSUPPORTED): save
     * puts the context's evolving fields under "bc." (checkpoint.h); restore reads them back
     * into a context freshly init'ed on the same assembly (configuration fields are set by
     * init; a stored one that differs fails with CDEM_ERR_CONFLICT) */
    cdem_status (*save)(const void *ctx, cdem_snapshot *snap, cdem_error *err);
    cdem_status (*restore)(void *ctx, const cdem_snapshot *snap, cdem_error *err);
    /* may be NULL (gravity keeps the direction the model gave it, mode.gravity_tilt): gravity's
     * acceleration (m/s^2, the model's frame) for deformation step k >= 1, g its magnitude: a
     * mode whose frame turns (a tilting margin) sets it here each step; it holds through
     * the steps that do not call the mode (sediment settling), and checkpoints keep it */
    void (*gravity)(const void *ctx, long k, double g, double *gx, double *gy);
    /* 1: the mode can be one of several boundary actors (it moves only the elements that
     * carry its model's moving_flag, adds its velocities when m->composed, and has an adopt
     * hook); 0: it runs alone */
    int composes;
    /* may be NULL; a run of several actors, after every actor's init: flags with the mode's
     * moving flag the other actors' boundary elements that ride on its moving block (e.g. a
     * later fault's ramp in a planar fault's hanging wall) */
    void (*adopt)(void *ctx, cdem_state *s);
    /* may be NULL (not a fault): the fault's trace from the parameters alone, a polyline from
     * where it meets the base (y = 0) up-dip to the height `height` (m) of the assembly, for
     * the checks of several faults (cdem_bc_rules: overlap, crossing) and their messages */
    cdem_status (*trace)(const cdem_params *p, const cdem_model *m, double height,
                         cdem_fault_polyline *out, cdem_error *err);
    /* Before the run, from the parameters alone (cdem_run_validate, cdem_bc_derive_model, the
     * summary), in this order in the parameter check: */
    /* may be NULL: the mode's own rules, one cdem_rule_add each (the message names the mode,
     * the keys and the fix) */
    void (*validate)(const cdem_params *p, cdem_rule_log *log);
    /* may be NULL: parameters the mode cannot run with, "section.key" (NULL-terminated); each
     * must be off (a switch or a choice) or 0 (a number); or CDEM_EXCLUDES_PROCESSES */
    const char *const *excludes;
    /* 1: boundary.inversion reverses the mode's sense; 0: inversion = on is refused */
    int inverts;
    /* may be NULL (cdem_model_mode_default): the mode's part of the model (base/model.h) */
    void (*derive)(const cdem_params *p, cdem_model_mode *out);
    /* may be NULL (no lines): the summary's lines of the mode after "mode: WORD", written
     * with cdem_summary_line (base/summary_line.h) */
    void (*describe)(const cdem_params *p, const cdem_model *m, FILE *out);
} cdem_bc_ops;

/* A boundary actor after the first: its mode instance, parameters, model and window. */
typedef struct {
    const cdem_bc_ops *ops;
    const char *name; /* the mode's word */
    void *ctx;        /* calloc'd state_size bytes */
    cdem_params *p;   /* its parameters (cdem_params_actor), owned */
    cdem_model m;     /* cdem_bc_actor_model */
    long k_start;     /* deformation steps before it moves */
    long k_stop;      /* its last deformation step (0: the run's last) */
} cdem_bc_actor;

/* The boundary of a run: its first actor (the mode of [boundary]) and the actors after it. */
typedef struct {
    const cdem_bc_ops *ops;  /* the first actor's; NULL before init */
    const char *name;        /* the first actor's word (common/modes.def), for messages */
    void *ctx;               /* the first actor's context, calloc'd state_size bytes */
    double lateral_pressure; /* N/m: boundary.confining_pressure when ops->confined, else 0 */
    long k_start, k_stop;    /* the first actor's window (0, 0 without one: to the end) */
    cdem_model m_first;      /* the first actor's model (the run's, without a window) */
    int n_more;              /* actors after the first */
    cdem_bc_actor *more;     /* owned, n_more of them */
    long k_now;              /* the deformation step being applied (the split moves read it) */
    uint32_t active_now;     /* the moving flags of the actors active in step k_now */
} cdem_bc;

/* The flag of the elements the actor whose model is m moves (a model made by hand, without a
 * moving_flag, is the first actor's: CDEM_FLAG_MOVING). */
static inline uint32_t cdem_bc_moving_flag(const cdem_model *m) {
    return m->moving_flag ? m->moving_flag : (uint32_t)CDEM_FLAG_MOVING;
}

/* The model boundary actor j (0-based) of p runs with: run_model's, with its moving flag and,
 * when it has a window, the window as its deformation (total_steps, total_displacement), and
 * its window in deformation steps (k_start < k <= k_stop; k_stop 0: to the run's end). */
void cdem_bc_actor_model(const cdem_params *pj, int j, const cdem_model *run_model, cdem_model *out,
                         long *k_start, long *k_stop);

/* The ops of a registered mode (every row of common/modes.def has them); CDEM_ERR_RANGE
 * naming the modes of parameter files for a value that is no mode. */
cdem_status cdem_bc_find(cdem_mode mode, const cdem_bc_ops **ops, cdem_error *err);

/* The modes' parameter rules (a cdem_params_rules of cdem_params_validate): p's mode's
 * validate, its excludes, and inversion = on with a mode that does not invert. */
void cdem_bc_rules(const cdem_params *p, cdem_rule_log *log);

/* An entry of a mode's excludes: no physical process (solver/process/) may run with the mode
 * (a test of the cover's material); a process's own rules ask cdem_bc_excludes and refuse
 * it, naming their keys (this layer knows no process). */
#define CDEM_EXCLUDES_PROCESSES "processes"

/* 1 when the mode's excludes list entry (a "section.key" or CDEM_EXCLUDES_PROCESSES); 0 for
 * a value that is no mode. */
int cdem_bc_excludes(cdem_mode mode, const char *entry);

/* The model of p (cdem_model_derive) with its mode's part (the mode's derive hook). */
cdem_status cdem_bc_derive_model(const cdem_params *p, cdem_model *m, cdem_error *err);

/* The summary's lines of p's mode (its describe hook; none without one). */
void cdem_bc_describe(const cdem_params *p, const cdem_model *m, FILE *out);

/* What the fault modes' summaries share: the sense and location of the fault, and the
 * inversion (its point and the net displacement). */
void cdem_bc_describe_fault(const cdem_params *p, const cdem_model *m, FILE *out);
void cdem_bc_describe_inversion(const cdem_params *p, const cdem_model *m, FILE *out);

/* Finds the mode of every actor of p (p->mode, then [boundary.N]'s), allocates their
 * contexts and runs their inits on s in order (each model's `composed` set when there are
 * several); with several actors, then their adopt hooks. */
cdem_status cdem_bc_init(cdem_bc *bc, const cdem_params *p, const cdem_model *m, cdem_state *s,
                         cdem_error *err);
/* k >= 1: the mode's apply (deformation step k); k <= 0: an equilibration step, the mode's
 * apply with k = 0 when it moves boundaries in equilibration (nothing otherwise). */
cdem_status cdem_bc_apply(cdem_bc *bc, cdem_state *s, long k, double du, double dt,
                          cdem_error *err);
/* 1 when cdem_bc_apply(bc, s, k, ...) touches no free element (ops->boundary_only, or an
 * equilibration step of a mode that does not move then): it may run before the drift. */
int cdem_bc_apply_is_boundary_only(const cdem_bc *bc, long k);
/* The per-element half of step k's apply (ops->step_move) when the mode is split and moves
 * anything in step k, else NULL. The caller then runs cdem_bc_step_begin once and the
 * returned function over every element (ranges in any order, on any threads) instead of
 * cdem_bc_apply: the same bits. */
typedef void (*cdem_bc_move_fn)(const void *ctx, cdem_state *s, long lo, long hi);
cdem_bc_move_fn cdem_bc_step_move_of(const cdem_bc *bc, long k);
/* The context the function of cdem_bc_step_move_of is called with. */
const void *cdem_bc_step_move_ctx(const cdem_bc *bc);
/* The once-only half of step k's apply (ops->step_begin; the same k, du, dt as
 * cdem_bc_apply). Only when cdem_bc_step_move_of returned a function. */
cdem_status cdem_bc_step_begin(cdem_bc *bc, long k, double du, double dt, cdem_error *err);
/* Gravity for deformation step k (>= 1) from the mode's gravity hook into *gx, *gy: 1 when the
 * mode sets it, 0 (nothing written) when it has no hook, k < 1 or bc is NULL. */
int cdem_bc_gravity(const cdem_bc *bc, long k, double g, double *gx, double *gy);
/* 1 when the mode moves boundaries during equilibration (ops->moves_in_equilibration). */
int cdem_bc_moves_in_equilibration(const cdem_bc *bc);
/* m: the first actor's net displacement, plus those of the actors after it. */
double cdem_bc_net_displacement(const cdem_bc *bc);
/* Runs the mode's begin_deformation hook (none: *n_remove = 0, keep untouched). */
cdem_status cdem_bc_begin_deformation(cdem_bc *bc, const cdem_state *s, unsigned char *keep,
                                      size_t *n_remove, cdem_error *err);
void cdem_bc_view(const cdem_bc *bc, FILE *out);
/* The mode's lateral (confining) pressure in N/m; 0 for a mode that is not confined or bc. */
double cdem_bc_lateral_pressure(const cdem_bc *bc);
/* The mode's measurements at a sample (both 0 without the hook). */
void cdem_bc_measure(cdem_bc *bc, const cdem_state *s, long step, int sample, double *axial_strain,
                     double *differential_stress);
/* Ramp factor of the confining pressure at completed step `step`: 0 up to equil/2, linear to
 * 1 at equil (the end of equilibration), 1 afterwards; equil <= 0: 1. */
static inline double cdem_bc_confining_ramp(long step, long equil) {
    if (equil <= 0 || step >= equil)
        return 1.0;
    const double h = 0.5 * (double)equil;
    const double f = ((double)step - h) / ((double)equil - h);
    return f <= 0.0 ? 0.0 : (f >= 1.0 ? 1.0 : f);
}
/* Checkpoints: the mode's name ("bc.mode") and its save/restore hooks; CDEM_ERR_UNSUPPORTED
 * naming the mode when it has none, CDEM_ERR_CONFLICT when the stored mode is another. */
cdem_status cdem_bc_snapshot_put(const cdem_bc *bc, cdem_snapshot *snap, cdem_error *err);
cdem_status cdem_bc_snapshot_get(cdem_bc *bc, const cdem_snapshot *snap, cdem_error *err);
/* Releases the context; bc may be NULL or never initialised. */
void cdem_bc_free(cdem_bc *bc);

/* The wall geometry every mode starts from: the base is the lowest row of wall elements
 * (y <= y_base + tol); the other wall elements are the lateral walls, left of x_mid
 * (left wall) or right of it (right wall). */
typedef struct {
    double y_base;       /* m, height of the base centres */
    double tol;          /* m, half the smallest radius: base-row tolerance in y */
    double r_base;       /* m, smallest radius of the base elements, > 0 */
    double x_mid;        /* m, midpoint of the extreme wall x positions */
    double x_min, x_max; /* m, extreme wall centres in x (the base ends) */
} cdem_bc_walls;

/* Finds the walls of s; CDEM_ERR_INVALID naming `mode` when s has no wall element. */
cdem_status cdem_bc_find_walls(const cdem_state *s, const cdem_model *m, const char *mode,
                               cdem_bc_walls *w, cdem_error *err);
/* 1 when element i (a wall element) belongs to the base row. */
static inline int cdem_bc_is_base(const cdem_bc_walls *w, const cdem_state *s, size_t i) {
    return s->y[i] <= w->y_base + w->tol;
}

/* The modes, one pointer each (bc_<id>.c), by the rows of common/modes.def. */
#define CDEM_MODE(ID, id, word, clock, description) extern const cdem_bc_ops *const cdem_bc_##id;
#define CDEM_TEST_MODE                              CDEM_MODE
#include "modes.def"
#undef CDEM_MODE
#undef CDEM_TEST_MODE

#endif
