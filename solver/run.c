/* run: see run.h. The run loop of cdem-run:
 *   derive the model -> build the assembly -> boundary mode init (adds its elements) ->
 *   writer -> increment 0 -> equilibration (walls still) -> at its last step: 24 layers,
 *   initial cohesion/bonds, increment n_equil -> start of deformation (the mode's optional
 *   begin_deformation hook, e.g. repose removes its walls) -> deformation (mode apply every step)
 * -> increments on the model schedule, time-series samples every series_interval steps;
 * with sedimentation, deposits every sediment_steps then settling_steps with the mode's motion
 * paused (phase "settling"; the mode's step counter k_def skips them; docs/solver.md 8). Stop
 * request: the current step finishes, a final increment is written, the stop reason "interrupted"
 * is recorded, the file closed, CDEM_ERR_INTERRUPTED returned. NaN/Inf: stop reason
 * "numerical-failure" with the diagnosis, file closed (every increment written so far stays
 * readable), CDEM_ERR_NUMERIC returned. opt->max_steps > 0 ends the run early
 * ("stopped-early", CDEM_OK). Checkpoints: after the step of every checkpoint_interval-th
 * increment and at a stop, cdem_run_capture (every module under its own prefix) ->
 * cdem_h5_writer_write_checkpoint; a resume re-runs the set-up, restores, reopens the file.
 * Progress goes to opt->log only (never stdout); the wall clock is read only for the progress
 * display, never for results. */
#include "run.h"

#include "assembly.h"
#include "bc.h"
#include "checkpoint.h"
#include "grid.h"
#include "h5format.h"
#include "integrate.h"
#include "model.h"
#include "sediment.h"
#include "stress.h"
#include "summary.h"

#include <limits.h>
#include <sys/stat.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifndef CDEM_VERSION
#define CDEM_VERSION "0.0.0"
#endif

/* Layout of the solver's checkpoint arrays (docs/reliability.md); bumped when a module stores
 * something new or changes a meaning, so a checkpoint of another layout is refused. */
#define CKPT_LAYOUT 1

/* Everything a run owns, released by cdem_run_close. */
struct cdem_run_ctx {
    const cdem_params *p;        /* parameters (caller's) */
    const cdem_run_options *opt; /* options (caller's) */
    cdem_model m;                /* derived constants */
    cdem_state s;                /* the elements */
    cdem_assembly_info info;     /* what the assembly generator built */
    cdem_bc bc;                  /* boundary mode */
    cdem_integrator it;          /* time stepper */
    cdem_h5_writer *w;           /* output file (NULL: none, staged runs of tests) */
    char *summary;               /* summary + mode view, malloc'd */
    char *params_eff;           /* the effective parameter file text (checkpoint check), malloc'd */
    cdem_snapshot *snap;        /* checkpoint buffer (NULL until the first checkpoint) */
    long step;                  /* last completed step */
    long step0;                 /* step at which this process started (progress rate only) */
    int next_inc;               /* number of the next increment to write */
    long next_inc_step;         /* step of increment next_inc on the model schedule */
    long last_written_step;     /* step of the last increment written (-1: none) */
    int last_ckpt_inc;          /* increment of the last checkpoint (0: none yet) */
    double base_tol_y;          /* m, wall elements with y below this are the base */
    long removed;               /* escaped elements removed */
    long eroded;                /* elements removed by erosion, whole run */
    double erosion_y;           /* m, erosion level (INFINITY until the end of equilibration) */
    double t_start, t_last_log; /* s, monotonic clock (progress display only) */
    long last_log_step;         /* step of the last progress output */
    /* measured speed of each phase (progress display only): equilibration and deformation
     * (with settling) run at different speeds, so the time left adds up each phase's own */
    double phase_time[2];  /* s spent in [0] equilibration, [1] deformation and settling */
    long phase_steps[2];   /* steps taken in each */
    double t_mark;         /* s, clock at the last accounting */
    long mark_step;        /* step at the last accounting */
    double element_steps;  /* sum over the steps taken by this process of the element count */
    int tty_line_open;     /* 1 when a progress line is drawn without newline */
    int tty_drawn;         /* 1 once a progress line has been drawn on the tty */
    cdem_sediment sed;     /* syn-tectonic sedimentation (disabled when off) */
    long k_def;            /* deformation steps applied by the mode (settling excluded) */
    int finished;          /* 1 once the stop reason is recorded (completed/stopped-early) */
    const char *stop_kind; /* "completed", "stopped-early", "interrupted" once recorded */
    int ckpt_off;          /* 1 when the file layer cannot store checkpoints */
};
typedef struct cdem_run_ctx run_ctx;

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int logging(const run_ctx *r) {
    return !r->opt->quiet && r->opt->log;
}

static void end_progress_line(run_ctx *r) {
    if (r->tty_line_open && r->opt->log) {
        fputc('\n', r->opt->log);
        r->tty_line_open = 0;
    }
}

static const char *phase_name(int phase) {
    return phase == CDEM_PHASE_EQUILIBRATION ? "equilibration"
           : phase == CDEM_PHASE_DEFORMATION ? "deformation"
                                             : "settling";
}

static int phase_of(const run_ctx *r, long step) {
    if (step <= r->m.equil_steps)
        return CDEM_PHASE_EQUILIBRATION;
    return cdem_sediment_settling(&r->sed, step) ? CDEM_PHASE_SETTLING : CDEM_PHASE_DEFORMATION;
}

/* Books the steps and time since the last call to the phase the run is in now (called every
 * 64 steps, so a phase change is attributed to within 64 steps). */
static void account_phase(run_ctx *r, double t) {
    const int k = phase_of(r, r->step) == CDEM_PHASE_EQUILIBRATION ? 0 : 1;
    r->phase_time[k] += t - r->t_mark;
    r->phase_steps[k] += r->step - r->mark_step;
    r->t_mark = t;
    r->mark_step = r->step;
}

/* Steps per second of phase k (0 equilibration, 1 deformation), or `fallback` before that
 * phase has run for a second. */
static double phase_rate(const run_ctx *r, int k, double fallback) {
    return r->phase_time[k] >= 1.0 ? (double)r->phase_steps[k] / r->phase_time[k] : fallback;
}

/* Seconds left: the equilibration steps left at equilibration's measured speed, the rest at
 * deformation's (equilibration's until deformation has been measured). */
static double time_left(const run_ctx *r, double overall) {
    const long eq_end = r->m.equil_steps, total = r->m.total_steps;
    const double eq_rate = phase_rate(r, 0, overall);
    const double def_rate = phase_rate(r, 1, eq_rate);
    const long eq_left = r->step < eq_end ? eq_end - r->step : 0;
    const long def_left = total - (r->step > eq_end ? r->step : eq_end);
    return (eq_rate > 0.0 ? (double)eq_left / eq_rate : 0.0) +
           (def_rate > 0.0 && def_left > 0 ? (double)def_left / def_rate : 0.0);
}

/* The progress line; ending NULL: "N s left", else the text that replaces it on the last
 * line ("completed", "stopped early", "interrupted"), so a run never ends on a time left.
 * The speed shown is the current phase's. */
static void progress_line(run_ctx *r, int force, const char *ending) {
    if (!logging(r))
        return;
    const double t = now_s();
    account_phase(r, t);
    const long total = r->m.total_steps;
    const double elapsed = t - r->t_start;
    const double overall = elapsed > 0.0 ? (double)(r->step - r->step0) / elapsed : 0.0;
    const int k = phase_of(r, r->step) == CDEM_PHASE_EQUILIBRATION ? 0 : 1;
    const double rate = phase_rate(r, k, overall);
    const double left = time_left(r, overall);
    const double net = cdem_bc_net_displacement(&r->bc);
    const int inc_done = r->next_inc - 1;
    char tail[64];
    if (ending)
        snprintf(tail, sizeof tail, "%s after %.0f s", ending, elapsed);
    else
        snprintf(tail, sizeof tail, "%.0f s left", left);
    if (r->opt->progress_is_tty) {
        /* the first line at once (a user sees the run start, and a short run still shows
         * its phases), then at most 4 redraws a second */
        if (!force && r->tty_drawn && t - r->t_last_log < 0.25)
            return;
        r->tty_drawn = 1;
        fprintf(r->opt->log,
                "\r\033[K%s, increment %d (0..%d), net displacement %.1f m, %zu elements, %.0f "
                "steps/s, %s",
                phase_name(phase_of(r, r->step)), inc_done, r->m.n_increments_total, net, r->s.n,
                rate, tail);
        fflush(r->opt->log);
        r->tty_line_open = 1;
    } else {
        const long tenth = total / 10 > 0 ? total / 10 : 1;
        if (!force && r->step - r->last_log_step < tenth && t - r->t_last_log < 30.0)
            return;
        fprintf(r->opt->log,
                "cdem-run: %s, step %ld/%ld, increment %d (0..%d), net displacement %.1f m, %zu "
                "elements, %.0f steps/s, %s\n",
                phase_name(phase_of(r, r->step)), r->step, total, inc_done, r->m.n_increments_total,
                net, r->s.n, rate, tail);
        fflush(r->opt->log);
        r->last_log_step = r->step;
    }
    r->t_last_log = t;
}

static void progress(run_ctx *r, int force) {
    progress_line(r, force, NULL);
}

/* 24 pre-growth layers of equal thickness between the lowest and highest free-element
 * centres at the end of equilibration; layer 1 at the bottom; walls keep layer 0. */
static void assign_layers(cdem_state *s) {
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        lo = fmin(lo, s->y[i]);
        hi = fmax(hi, s->y[i]);
    }
    if (!(hi > lo))
        return;
    const double th = (hi - lo) / CDEM_PREGROWTH_LAYERS;
    /* layer k - 1 is row k - 1 of bands of height th from lo (off the bands: the end ones) */
    const cdem_grid layers = {
        .x0 = 0.0, .y0 = lo, .cell = th, .nx = 1, .ny = CDEM_PREGROWTH_LAYERS};
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY) {
            s->layer[i] = 0;
            continue;
        }
        s->layer[i] = (int32_t)cdem_grid_row(&layers, s->y[i]) + 1;
    }
}

/* Erosion before an increment of the deformation phase: every free element whose centre is
 * above erosion_y is removed (integrator removal path), the count logged. */
static cdem_status erode(run_ctx *r, cdem_error *err) {
    if (!r->p->erosion || !isfinite(r->erosion_y) || r->step <= r->m.equil_steps)
        return CDEM_OK;
    long count = 0;
    CDEM_TRY(cdem_integrator_erode(&r->it, &r->s, r->erosion_y, &count, err));
    r->eroded += count;
    if (logging(r) && count > 0) {
        end_progress_line(r);
        fprintf(r->opt->log,
                "cdem-run: erosion removed %ld elements above y = %.6g m before increment %d at "
                "step %ld (%ld eroded so far)\n",
                count, r->erosion_y, r->next_inc, r->step, r->eroded);
    }
    return CDEM_OK;
}

/* End of equilibration: the erosion level is erosion_base_level x the height of the
 * equilibrated assembly, measured from the lowest free-element centre to the highest one
 * (the span of the 24 layers): y = lo + level (hi - lo). */
static void set_erosion_level(run_ctx *r) {
    r->erosion_y = INFINITY;
    if (!r->p->erosion)
        return;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < r->s.n; i++) {
        if (r->s.flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        lo = fmin(lo, r->s.y[i]);
        hi = fmax(hi, r->s.y[i]);
    }
    if (hi >= lo)
        r->erosion_y = lo + r->p->erosion_base_level * (hi - lo);
}

static cdem_status write_increment(run_ctx *r, cdem_error *err) {
    CDEM_TRY(erode(r, err));
    if (r->p->calculate_stress)
        CDEM_TRY(cdem_stress_compute(&r->it.nb, &r->s, err));
    cdem_increment_info inf;
    memset(&inf, 0, sizeof inf);
    inf.number = r->next_inc;
    inf.step = r->step;
    inf.time = (double)r->step * r->m.dt;
    inf.phase = phase_of(r, r->step);
    inf.net_displacement = cdem_bc_net_displacement(&r->bc);
    inf.sea_level = cdem_sediment_sea_level(&r->sed, r->step);
    inf.n_elements = (int64_t)r->s.n;
    inf.has_stress = r->s.has_stress;
    cdem_bc_measure(&r->bc, &r->s, r->step, 0, &inf.axial_strain, &inf.differential_stress);
    if (r->w)
        CDEM_TRY(cdem_h5_writer_write_increment(r->w, &inf, &r->s, err));
    r->next_inc++;
    r->last_written_step = r->step;
    return CDEM_OK;
}

static cdem_status write_sample(run_ctx *r, cdem_error *err) {
    cdem_series_sample q;
    memset(&q, 0, sizeof q);
    q.step = r->step;
    q.time = (double)r->step * r->m.dt;
    const cdem_state *s = &r->s;
    double ke = 0.0, bfx = 0.0, bfy = 0.0, gfx = 0.0, gfy = 0.0;
    for (size_t i = 0; i < s->n; i++) { /* serial, fixed order: reproducible sums */
        const uint32_t f = s->flags[i];
        if (!(f & CDEM_FLAGS_BOUNDARY)) {
            ke += 0.5 * s->mass[i] * (s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i]);
        } else if (f & CDEM_FLAG_MOVING) {
            bfx += s->fx[i];
            bfy += s->fy[i];
        } else if ((f & CDEM_FLAG_WALL) && s->y[i] <= r->base_tol_y) {
            gfx += s->fx[i];
            gfy += s->fy[i];
        }
    }
    long contacts = 0, bonds = 0;
    cdem_integrator_count(&r->it, &contacts, &bonds);
    q.kinetic_energy = ke;
    q.contacts = contacts;
    q.bonds = bonds;
    q.n_elements = (int64_t)s->n;
    q.net_displacement = cdem_bc_net_displacement(&r->bc);
    q.boundary_force_x = bfx;
    q.boundary_force_y = bfy;
    q.base_force_x = gfx;
    q.base_force_y = gfy;
    q.sea_level = cdem_sediment_sea_level(&r->sed, r->step);
    cdem_bc_measure(&r->bc, s, r->step, 1, &q.axial_strain, &q.differential_stress);
    return r->w ? cdem_h5_writer_append_series(r->w, &q, err) : CDEM_OK;
}

/* The element count of increment 0 (docs/format.md, "Counting"): free elements and the
 * rest (walls, fault ramps, mylar, footwall display), after the mode has added its own. */
static void count_kinds(const cdem_state *s, long *n_free, long *n_boundary) {
    *n_free = *n_boundary = 0;
    for (size_t i = 0; i < s->n; i++)
        ++*((s->flags[i] & CDEM_FLAGS_BOUNDARY) ? n_boundary : n_free);
}

static cdem_status make_summary(run_ctx *r, cdem_error *err) {
    char *text = NULL;
    long n_free, n_boundary;
    count_kinds(&r->s, &n_free, &n_boundary);
    CDEM_TRY(cdem_summary_text(r->p, &r->m, n_free, n_boundary, 0, &text, err));
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) {
        free(text);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the summary text");
    }
    fputs(text, f);
    const size_t tl = strlen(text);
    if (tl == 0 || text[tl - 1] != '\n')
        fputc('\n', f);
    cdem_bc_view(&r->bc, f);
    fprintf(f,
            "Solver: velocity Verlet, dt %.6g s, Verlet-list skin %.4g m, %s contacts; "
            "cohesion/bonds created for touching pairs at the end of equilibration%s.\n",
            r->m.dt, r->it.nb.skin,
            r->p->material == CDEM_MATERIAL_BONDED ? "bonded" : "frictional-cohesive",
            r->p->sedimentation ? " and for the pairs of each sediment deposit at the end of its "
                                  "settling (settling steps count in the runtime; boundaries "
                                  "still)"
                                : "");
    fclose(f);
    free(text);
    r->summary = buf;
    return CDEM_OK;
}

static void log_removed(run_ctx *r) {
    if (r->it.n_removed_last == 0)
        return;
    r->removed += (long)r->it.n_removed_last;
    if (!logging(r))
        return;
    end_progress_line(r);
    for (size_t k = 0; k < r->it.n_removed_last; k++)
        fprintf(r->opt->log,
                "cdem-run: removed escaping element id %d at step %ld (%ld removed so far)\n",
                (int)r->it.removed_ids[k], r->step, r->removed);
}

/* Instability guard: with a stable time step no element moves its own radius in one step
 * (free fall over the tallest assembly at the largest gravity stays below ~0.7 radius);
 * beyond that contacts are skipped and the run is garbage even while every number is
 * still finite (the escaping elements are removed and the run would go on). The test
 * (|v| dt > r) is made by the integrator's force pass (unstable_guard, set up in setup)
 * while the velocities are in cache; it reports the lowest such index, so the element
 * reported is the same for any thread count. */
static cdem_status check_unstable(const run_ctx *r, cdem_error *err) {
    const cdem_state *s = &r->s;
    const long i = r->it.unstable_index;
    if (i < 0 || (size_t)i >= s->n)
        return CDEM_OK;
    const double dt = r->m.dt;
    const double d2 = (s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i]) * dt * dt;
    return CDEM_FAIL(err, CDEM_ERR_NUMERIC,
                     "element id %d moved %.3g m in one time step (more than its radius %.3g m) "
                     "at step %ld: the simulation is unstable; likely cause: the time step is "
                     "too large for the spring constants and element masses",
                     (int)s->id[i], sqrt(d2), s->radius[i], r->step);
}

/* Everything before the first step, for a fresh run and a resumed one alike: the model, the
 * assembly (regenerated from the seed), the mode, the stepper and the summary. No file yet. */
static cdem_status setup(run_ctx *r, cdem_error *err) {
    const cdem_params *p = r->p;
    const cdem_run_options *opt = r->opt;
    CDEM_TRY(cdem_model_derive(p, &r->m, err));
    if (r->opt->dt_factor > 0.0)
        r->m.dt *= r->opt->dt_factor; /* fault injection (tests): a time step too large */
    CDEM_TRY(cdem_sediment_init(&r->sed, p, &r->m, err));
    CDEM_TRY(cdem_state_init(&r->s, 1024, p->calculate_stress, err));
    CDEM_TRY(cdem_assembly_build(p, &r->m, &r->s, &r->info, err));
    long n_weak = 0;
    CDEM_TRY(cdem_contact_assign_weak(p, &r->s, &n_weak, err));
    if (logging(r) && p->weak_interval != CDEM_WEAK_OFF)
        fprintf(opt->log, "cdem-run: weak/light interval: %ld elements flagged weak\n", n_weak);
    r->erosion_y = INFINITY;
    double ywall = INFINITY;
    for (size_t i = 0; i < r->s.n; i++)
        if (r->s.flags[i] & CDEM_FLAG_WALL)
            ywall = fmin(ywall, r->s.y[i]);
    r->base_tol_y = ywall + 0.5 * r->m.radius[0];
    CDEM_TRY(cdem_bc_init(&r->bc, p, &r->m, &r->s, err));
    CDEM_TRY(cdem_integrator_init(&r->it, p, &r->m, err));
    r->it.unstable_guard = 1; /* check_unstable */
    r->it.equilibrating = 1;  /* the packing phase's law until the end of equilibration */
    if (opt->par_min > 0)
        r->it.par_min = opt->par_min;
    cdem_integrator_enable_escape(&r->it);
    CDEM_TRY(cdem_integrator_set_overburden(&r->it, p->overburden_pressure, err));
    CDEM_TRY(cdem_integrator_set_confining(&r->it, cdem_bc_lateral_pressure(&r->bc),
                                           r->m.equil_steps, err));
    CDEM_TRY(make_summary(r, err));
    size_t len = 0;
    FILE *f = open_memstream(&r->params_eff, &len);
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the parameter text");
    cdem_params_write(p, f);
    fclose(f);
    r->t_start = r->t_last_log = r->t_mark = now_s();
    r->last_written_step = -1;
    return CDEM_OK;
}

/* "; continue it with: cdem-run --resume FILE" when the file holds a checkpoint to continue
 * from, else why it cannot be continued; "" without a file. */
static void resume_hint(const run_ctx *r, char *buf, size_t cap) {
    buf[0] = '\0';
    if (!r->opt->output_path)
        return;
    if (!r->ckpt_off && r->p->checkpoint_interval > 0)
        snprintf(buf, cap, "; continue it with: cdem-run --resume %s", r->opt->output_path);
    else
        snprintf(buf, cap,
                 "; it cannot be continued (no checkpoints: output.checkpoint_interval = %d)",
                 r->p->checkpoint_interval);
}

/* A fresh run: creates the file, computes the first forces, writes increment 0. */
static cdem_status start_fresh(run_ctx *r, cdem_error *err) {
    const cdem_run_meta meta = {
        .params = r->p,
        .params_text = r->opt->params_text,
        .summary = r->summary,
        .program_version = CDEM_VERSION,
        .source = "cdem-run",
    };
    if (r->opt->output_path && !r->opt->ignore_free_space) {
        /* A full disk is reported now, not hours into the run: the file, its checkpoint
         * slots and its sidecar. */
        const double need =
            cdem_h5_estimate_run_space((double)r->s.n, (double)r->m.n_increments_total + 1.0,
                                       r->p->calculate_stress, r->p->checkpoint_interval > 0);
        cdem_status st = cdem_h5_check_free_space(r->opt->output_path, need, err);
        if (st == CDEM_ERR_IO) { /* too little space (other codes: the folder itself) */
            char msg[CDEM_ERROR_MSG_MAX];
            snprintf(msg, sizeof msg, "%s", err ? err->msg : "not enough free space");
            return CDEM_FAIL(err, CDEM_ERR_IO,
                             "%.400s (estimated from %zu elements x %d increments); free some "
                             "space, write elsewhere (-o) or run anyway with --ignore-free-space",
                             msg, r->s.n, r->m.n_increments_total + 1);
        }
        CDEM_TRY(st);
    }
    if (r->opt->output_path) {
        CDEM_TRY(
            cdem_h5_writer_create_checked(r->opt->output_path, &meta, r->opt->replace, &r->w, err));
        cdem_h5_writer_set_sync(r->w, !r->opt->no_fsync);
    }
    r->step = 0;
    r->next_inc = 0;
    CDEM_TRY(cdem_integrator_prime(&r->it, &r->s, err));
    cdem_integrator_mark_initial(&r->it, &r->s);
    log_removed(r);
    CDEM_TRY(write_increment(r, err));
    CDEM_TRY(write_sample(r, err));
    r->next_inc_step = cdem_model_increment_step(&r->m, r->next_inc);
    return CDEM_OK;
}

cdem_status cdem_run_capture(const cdem_run_ctx *r, cdem_snapshot *snap, cdem_error *err) {
    if (!r || !snap)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_capture: NULL argument");
    cdem_snapshot_clear(snap);
    const char *P = "run";
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "layout", CKPT_LAYOUT, err));
    CDEM_TRY(cdem_ckpt_put_text(snap, P, "version", CDEM_VERSION, err));
    CDEM_TRY(cdem_ckpt_put_text(snap, P, "params", r->params_eff, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "step", r->step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "next_inc", r->next_inc, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "next_inc_step", r->next_inc_step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "last_written_step", r->last_written_step, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "last_ckpt_inc", r->last_ckpt_inc, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "removed", r->removed, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "eroded", r->eroded, err));
    CDEM_TRY(cdem_ckpt_put_i64(snap, P, "k_def", r->k_def, err));
    CDEM_TRY(cdem_ckpt_put_f64(snap, P, "erosion_y", r->erosion_y, err));
    CDEM_TRY(cdem_ckpt_state_put(&r->s, r->it.boundary_forces, snap, err));
    CDEM_TRY(cdem_integrator_snapshot_put(&r->it, snap, err));
    CDEM_TRY(cdem_bc_snapshot_put(&r->bc, snap, err));
    return cdem_sediment_snapshot_put(&r->sed, snap, err);
}

/* Replaces the state of a set-up run by the checkpoint's. */
static cdem_status restore(run_ctx *r, const cdem_snapshot *snap, cdem_error *err) {
    const char *P = "run";
    int64_t layout = 0;
    CDEM_TRY(cdem_ckpt_get_i64(snap, P, "layout", &layout, err));
    if (layout != CKPT_LAYOUT)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "checkpoint layout %lld: this cdem-run (%s) reads layout %d only; resume "
                         "with the version that wrote the file",
                         (long long)layout, CDEM_VERSION, CKPT_LAYOUT);
    const cdem_snapshot_array *ver = NULL;
    CDEM_TRY(cdem_ckpt_get_array(snap, P, "version", CDEM_SNAP_U8, SIZE_MAX, &ver, err));
    if (ver->count != strlen(CDEM_VERSION) || memcmp(ver->data, CDEM_VERSION, ver->count) != 0)
        return CDEM_FAIL(err, CDEM_ERR_VERSION,
                         "the checkpoint was written by cdem-run %.*s, this is cdem-run %s: a run "
                         "resumes bit-identically only with the version that started it",
                         (int)(ver->count > 64 ? 64 : ver->count), (const char *)ver->data,
                         CDEM_VERSION);
    CDEM_TRY(cdem_ckpt_check_text(snap, P, "params", r->params_eff, "parameter set", err));
    const long total = r->m.total_steps;
    int64_t step = 0, next_inc = 0, next_inc_step = 0, lws = 0, lci = 0, removed = 0, eroded = 0,
            k_def = 0;
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "step", 0, total, &step, err));
    CDEM_TRY(
        cdem_ckpt_get_range(snap, P, "next_inc", 1, r->m.n_increments_total + 1, &next_inc, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "next_inc_step", 0, INT64_MAX, &next_inc_step, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "last_written_step", -1, step, &lws, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "last_ckpt_inc", 0, next_inc, &lci, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "removed", 0, INT64_MAX, &removed, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "eroded", 0, INT64_MAX, &eroded, err));
    CDEM_TRY(cdem_ckpt_get_range(snap, P, "k_def", 0, step, &k_def, err));
    CDEM_TRY(cdem_ckpt_get_f64(snap, P, "erosion_y", &r->erosion_y, err));
    CDEM_TRY(cdem_ckpt_state_get(&r->s, snap, err));
    CDEM_TRY(cdem_integrator_snapshot_get(&r->it, snap, &r->s, err));
    if (r->it.step != (long)step)
        return CDEM_FAIL(err, CDEM_ERR_FORMAT,
                         "checkpoint run.step = %lld but it.step = %ld (corrupt checkpoint)",
                         (long long)step, r->it.step);
    CDEM_TRY(cdem_bc_snapshot_get(&r->bc, snap, err));
    CDEM_TRY(cdem_sediment_snapshot_get(&r->sed, snap, err));
    r->step = r->step0 = r->mark_step = (long)step;
    r->next_inc = (int)next_inc;
    r->next_inc_step = (long)next_inc_step;
    r->last_written_step = (long)lws;
    r->last_ckpt_inc = (int)lci;
    r->removed = (long)removed;
    r->eroded = (long)eroded;
    r->k_def = (long)k_def;
    return CDEM_OK;
}

/* Captures the run and stores it in the file as the checkpoint of the increment written last.
 * scheduled = 1: a periodic checkpoint (it records itself in last_ckpt_inc, which sets the
 * schedule of the next); 0: the checkpoint of a stop (signal, max_steps), which leaves the
 * schedule as it is so a resumed run writes the same periodic checkpoints. */
static cdem_status write_checkpoint(run_ctx *r, int scheduled, cdem_error *err) {
    if (!r->snap)
        CDEM_TRY(cdem_snapshot_alloc(&r->snap, err));
    const int saved = r->last_ckpt_inc;
    if (scheduled)
        r->last_ckpt_inc = r->next_inc - 1; /* the checkpoint records itself */
    cdem_status st = cdem_run_capture(r, r->snap, err);
    if (st == CDEM_OK)
        st = cdem_h5_writer_write_checkpoint(r->w, r->snap, err);
    if (st == CDEM_ERR_UNSUPPORTED) {
        /* a file layer without checkpoints: say so once and run on without them */
        r->ckpt_off = 1;
        if (logging(r)) {
            end_progress_line(r);
            fprintf(r->opt->log, "cdem-run: no checkpoints will be written: %s\n",
                    err ? err->msg : "unsupported");
        }
        if (err)
            cdem_error_clear(err);
        st = CDEM_OK;
    }
    if (st != CDEM_OK) {
        r->last_ckpt_inc = saved;
        return st;
    }
    return CDEM_OK;
}

static cdem_status run_loop(run_ctx *r, long until, cdem_error *err) {
    const cdem_params *p = r->p;
    const cdem_run_options *opt = r->opt;
    const long total = r->m.total_steps;
    const long equil = r->m.equil_steps;
    const long interval = p->series_interval > 0 ? p->series_interval : 1;
    while (r->step < total && r->step < until && !r->finished) {
        const long step = r->step + 1;
        /* settling after a sediment deposit: boundaries still, not a deformation step */
        const int deforming = step > equil && !cdem_sediment_settling(&r->sed, step);
        if (deforming)
            r->k_def++;
        if (step == equil + 1) {
            /* the mode's start-of-deformation event (e.g. repose removes its walls) */
            size_t nrem = 0;
            CDEM_TRY(cdem_integrator_begin_deformation(&r->it, &r->s, &r->bc, &nrem, err));
            if (nrem > 0 && logging(r)) {
                end_progress_line(r);
                fprintf(opt->log,
                        "cdem-run: start of deformation: %zu boundary elements removed by the %s "
                        "mode, %zu elements left\n",
                        nrem, r->bc.ops->name, r->s.n);
            }
        }
        /* wall forces are summed only on the steps whose sample reports them, and on every
         * equilibration step of a mode that moves boundaries then (biaxial servo platens) */
        const int eq_moves = step <= equil && cdem_bc_moves_in_equilibration(&r->bc);
        /* the packing phase's law (settling friction) up to the end of equilibration; the
         * damping of deformation steps (physics.deformation_damping) */
        r->it.equilibrating = step <= equil;
        r->it.damping_factor = deforming ? p->deformation_damping : 1.0;
        r->it.boundary_forces = (step % interval == 0) || eq_moves;
        cdem_status st =
            cdem_integrator_step(&r->it, &r->s, (deforming || eq_moves) ? &r->bc : NULL,
                                 deforming ? r->k_def : 0, r->m.displacement_per_step, err);
        if (st != CDEM_OK)
            return st;
        r->step = step;
        CDEM_TRY(check_unstable(r, err));
        log_removed(r);
        if (step == equil) {
            assign_layers(&r->s);
            cdem_integrator_classify(&r->it, &r->s);
            set_erosion_level(r);
            cdem_sediment_begin(&r->sed, &r->s);
            long made = cdem_integrator_make_cohesive(&r->it, &r->s);
            end_progress_line(r); /* on a terminal the line is kept above the progress line */
            if (logging(r))
                fprintf(opt->log, "cdem-run: end of equilibration at step %ld: %ld %s created\n",
                        step, made,
                        p->material == CDEM_MATERIAL_BONDED ? "bonds" : "cohesive contacts");
        }
        const long settled = cdem_sediment_after_step(&r->sed, &r->it, &r->s, step);
        if (settled > 0 && logging(r)) {
            end_progress_line(r);
            fprintf(opt->log, "cdem-run: end of settling at step %ld: %ld %s created\n", step,
                    settled, p->material == CDEM_MATERIAL_BONDED ? "bonds" : "cohesive contacts");
        }
        if (step % interval == 0)
            CDEM_TRY(write_sample(r, err));
        while (r->next_inc <= r->m.n_increments_total && step >= r->next_inc_step) {
            CDEM_TRY(write_increment(r, err));
            r->next_inc_step = cdem_model_increment_step(&r->m, r->next_inc);
        }
        if (cdem_sediment_due(&r->sed, step)) {
            long added = 0;
            CDEM_TRY(cdem_sediment_event(&r->sed, &r->it, &r->s, step, r->next_inc, &added, err));
            if (logging(r)) {
                end_progress_line(r);
                fprintf(opt->log,
                        "cdem-run: sedimentation at step %ld: %ld growth elements (layer %d) "
                        "below sea level %.6g m, settling %ld steps\n",
                        step, added, (int)r->sed.settling_layer,
                        cdem_sediment_sea_level(&r->sed, step), r->sed.settling_steps);
            }
        }
        /* checkpoint: after the whole step (deposit included) that wrote an increment, every
         * checkpoint_interval increments; reading the state only, it never changes results */
        if (r->w && !r->ckpt_off && p->checkpoint_interval > 0 && r->last_written_step == step &&
            step < total && r->next_inc - 1 - r->last_ckpt_inc >= p->checkpoint_interval)
            CDEM_TRY(write_checkpoint(r, 1, err));
        r->element_steps += (double)r->s.n;
        if (step % 64 == 0)
            progress(r, 0);
        /* a stop (signal, max_steps) first checkpoints the state of this step, before the
         * final increment (whose erosion would change it): a resume continues from here and
         * drops that unscheduled increment */
        const int stopping = (opt->stop_requested && *opt->stop_requested) ||
                             (opt->max_steps > 0 && step >= opt->max_steps && step < total);
        if (stopping && r->w && !r->ckpt_off && p->checkpoint_interval > 0 && step < total)
            CDEM_TRY(write_checkpoint(r, 0, err));
        if (opt->stop_requested && *opt->stop_requested) {
            if (r->last_written_step != step)
                CDEM_TRY(write_increment(r, err));
            char detail[256];
            snprintf(detail, sizeof detail,
                     "stopped by a signal after step %ld of %ld (%s), last increment %d", step,
                     total, phase_name(phase_of(r, step)), r->next_inc - 1);
            if (r->w)
                CDEM_TRY(cdem_h5_writer_set_stop_reason(r->w, "interrupted", detail, err));
            r->stop_kind = "interrupted";
            char how[CDEM_PATH_MAX + 160];
            resume_hint(r, how, sizeof how);
            return CDEM_FAIL(err, CDEM_ERR_INTERRUPTED, "%s; the file %s is valid%s", detail,
                             opt->output_path ? opt->output_path : "(none)", how);
        }
        if (opt->max_steps > 0 && step >= opt->max_steps && step < total) {
            if (r->last_written_step != step)
                CDEM_TRY(write_increment(r, err));
            char detail[256];
            snprintf(detail, sizeof detail, "max_steps = %ld reached at step %ld of %ld",
                     opt->max_steps, step, total);
            if (r->w)
                CDEM_TRY(cdem_h5_writer_set_stop_reason(r->w, "stopped-early", detail, err));
            r->finished = 1;
            r->stop_kind = "stopped-early";
            return CDEM_OK;
        }
    }
    if (r->finished || r->step < total)
        return CDEM_OK;
    if (r->last_written_step != r->step)
        CDEM_TRY(write_increment(r, err));
    char detail[256];
    snprintf(detail, sizeof detail,
             "%ld steps, %d increments, %ld escaping elements removed, %ld eroded", r->step,
             r->next_inc - 1, r->removed, r->eroded);
    r->finished = 1;
    r->stop_kind = "completed";
    return r->w ? cdem_h5_writer_set_stop_reason(r->w, "completed", detail, err) : CDEM_OK;
}

static void run_release(run_ctx *r) {
    cdem_integrator_free(&r->it);
    cdem_sediment_free(&r->sed);
    cdem_bc_free(&r->bc);
    cdem_state_free(&r->s);
    cdem_snapshot_free(r->snap);
    free(r->summary);
    free(r->params_eff);
    free(r);
}

static cdem_status open_body(run_ctx *r, const cdem_snapshot *resume, cdem_error *err) {
    CDEM_TRY(setup(r, err));
    if (!resume)
        return start_fresh(r, err);
    CDEM_TRY(restore(r, resume, err));
    if (r->opt->output_path) {
        CDEM_TRY(cdem_h5_writer_reopen(r->opt->output_path, r->next_inc - 1, r->step, &r->w, err));
        cdem_h5_writer_set_sync(r->w, !r->opt->no_fsync);
    }
    if (logging(r))
        fprintf(r->opt->log, "cdem-run: resumed %s at step %ld of %ld, after increment %d\n",
                r->opt->output_path ? r->opt->output_path : "a run", r->step, r->m.total_steps,
                r->next_inc - 1);
    return CDEM_OK;
}

cdem_status cdem_run_open(const cdem_params *p, const cdem_run_options *opt,
                          const cdem_snapshot *resume, cdem_run_ctx **out, cdem_error *err) {
    if (!out)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_open: NULL output pointer");
    *out = NULL;
    if (!p || !opt)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_open: parameters and options required");
    run_ctx *r = calloc(1, sizeof *r);
    if (!r)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for a run");
    r->p = p;
    r->opt = opt;
    cdem_status st = open_body(r, resume, err);
    if (st != CDEM_OK) {
        if (r->w) {
            cdem_error e2;
            cdem_error_clear(&e2);
            (void)cdem_h5_writer_close(r->w, &e2);
        }
        run_release(r);
        return st;
    }
    *out = r;
    return CDEM_OK;
}

cdem_status cdem_run_advance(cdem_run_ctx *r, long until_step, cdem_error *err) {
    if (!r)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_advance: NULL run");
    return run_loop(r, until_step, err);
}

long cdem_run_current_step(const cdem_run_ctx *r) {
    return r ? r->step : 0;
}

long cdem_run_total_steps(const cdem_run_ctx *r) {
    return r ? r->m.total_steps : 0;
}

/* The last line of a run's log: the file, its size, the increments it holds and how the run
 * ended, with how to continue one that stopped early. */
static void log_wrote(const run_ctx *r, cdem_status st, int had_writer) {
    if (!logging(r) || !had_writer || !r->opt->output_path)
        return;
    struct stat sb;
    const double mb = stat(r->opt->output_path, &sb) == 0 ? (double)sb.st_size / 1e6 : NAN;
    const char *how = st == CDEM_OK && r->stop_kind ? r->stop_kind
                      : st == CDEM_ERR_INTERRUPTED  ? "interrupted"
                      : st == CDEM_ERR_NUMERIC      ? "numerical-failure"
                      : st == CDEM_ERR_IO           ? "write-failure"
                                                    : "error";
    char hint[CDEM_PATH_MAX + 160] = "";
    if (st == CDEM_OK && r->stop_kind && !strcmp(r->stop_kind, "stopped-early"))
        resume_hint(r, hint, sizeof hint);
    const double wall = now_s() - r->t_start;
    fprintf(r->opt->log,
            "cdem-run: wrote %s (%.1f MB; %d increments, numbered 0..%d; %zu elements at the end; "
            "%ld steps in %.1f s wall time, %.3g element-steps/s; stop reason: %s%s)\n",
            r->opt->output_path, mb, r->next_inc, r->next_inc - 1, r->s.n, r->step - r->step0, wall,
            wall > 0.0 ? r->element_steps / wall : 0.0, how, hint);
}

cdem_status cdem_run_close(cdem_run_ctx *r, cdem_status st, cdem_error *err) {
    if (!r)
        return st;
    if (logging(r)) {
        const char *ending = st == CDEM_OK && r->stop_kind && !strcmp(r->stop_kind, "stopped-early")
                                 ? "stopped early"
                             : st == CDEM_OK              ? "completed"
                             : st == CDEM_ERR_INTERRUPTED ? "interrupted"
                                                          : "failed";
        progress_line(r, 1, ending);
        end_progress_line(r);
    }
    const int had_writer = r->w != NULL;
    if (r->w) {
        if (st == CDEM_ERR_NUMERIC && err) {
            /* the numbers behind "time step too large": what a user can change */
            size_t len = strlen(err->msg);
            snprintf(err->msg + len, sizeof err->msg - len,
                     " (time step %g s, spring constant %g N/m, smallest element mass %g kg per "
                     "metre%s)",
                     r->m.dt, r->m.kn, r->m.min_mass,
                     r->p->keep_constants && r->p->unit_scaling < 1000.0
                         ? "; keep_constants = on keeps the 1000 m spring and damping constants "
                           "at this smaller unit_scaling: try keep_constants = off"
                         : "");
        }
        if (st != CDEM_OK && st != CDEM_ERR_INTERRUPTED) {
            /* record the diagnosis in the file; keep the original error */
            cdem_error e2;
            cdem_error_clear(&e2);
            (void)cdem_h5_writer_set_stop_reason(r->w,
                                                 st == CDEM_ERR_NUMERIC ? "numerical-failure"
                                                 : st == CDEM_ERR_IO    ? "write-failure"
                                                                        : "error",
                                                 err ? err->msg : cdem_status_str(st), &e2);
        }
        cdem_error e3;
        cdem_error_clear(&e3);
        cdem_status cst = cdem_h5_writer_close(r->w, st == CDEM_OK ? err : &e3);
        if (st == CDEM_OK)
            st = cst;
        r->w = NULL;
        if (cst == CDEM_OK)
            log_wrote(r, st, had_writer);
    }
    run_release(r);
    return st;
}

cdem_status cdem_run(const cdem_params *p, const cdem_run_options *opt, cdem_error *err) {
    if (!p || !opt || !opt->output_path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_run: parameters, options and an output path are required");
    cdem_run_ctx *r = NULL;
    CDEM_TRY(cdem_run_open(p, opt, NULL, &r, err));
    cdem_status st = cdem_run_advance(r, LONG_MAX, err);
    return cdem_run_close(r, st, err);
}

cdem_status cdem_run_resume(const char *path, const cdem_run_options *opt, cdem_error *err) {
    if (!path || !opt)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_resume: a file and options are required");
    cdem_h5_reader *rd = NULL;
    CDEM_TRY(cdem_h5_reader_open(path, &rd, err));
    cdem_params p;
    cdem_snapshot *snap = NULL;
    int32_t inc = 0;
    cdem_status st = CDEM_OK;
    const char *stop = cdem_h5_reader_stop_reason(rd);
    if (strcmp(stop, "completed") == 0)
        st = CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                       "%s: the run already completed (stop reason \"completed\"): there is "
                       "nothing to resume",
                       path);
    if (st == CDEM_OK && strcmp(cdem_h5_reader_source(rd), "cdem-run") != 0)
        st = CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                       "%s: written by \"%s\", not by cdem-run: only cdem-run files can be resumed",
                       path, cdem_h5_reader_source(rd));
    if (st == CDEM_OK)
        st = cdem_h5_reader_params(rd, &p, err);
    if (st == CDEM_OK)
        st = cdem_params_validate(&p, err);
    if (st == CDEM_OK)
        st = cdem_snapshot_alloc(&snap, err);
    if (st == CDEM_OK) {
        st = cdem_h5_reader_read_checkpoint(rd, snap, &inc, err);
        if (st == CDEM_ERR_NOTFOUND)
            st = CDEM_FAIL(
                err, CDEM_ERR_NOTFOUND,
                "%s has no checkpoint to resume from (its output.checkpoint_interval is %d "
                "increments, 0 = none): it stopped before its first checkpoint or was "
                "written without; run the model again from the start",
                path, p.checkpoint_interval);
    }
    cdem_h5_reader_close(rd);
    if (st == CDEM_OK) {
        int64_t next_inc = 0;
        st = cdem_ckpt_get_i64(snap, "run", "next_inc", &next_inc, err);
        if (st == CDEM_OK && next_inc - 1 != inc)
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: the checkpoint says it follows increment %lld but is stored for "
                           "increment %d (corrupt checkpoint)",
                           path, (long long)(next_inc - 1), (int)inc);
    }
    if (st != CDEM_OK) {
        cdem_snapshot_free(snap);
        return st;
    }
    cdem_run_options o = *opt;
    o.output_path = path;
    cdem_run_ctx *r = NULL;
    st = cdem_run_open(&p, &o, snap, &r, err);
    cdem_snapshot_free(snap);
    if (st != CDEM_OK)
        return st;
    st = cdem_run_advance(r, LONG_MAX, err);
    return cdem_run_close(r, st, err);
}

cdem_status cdem_run_count_elements(const cdem_params *p, long *n_internal, long *n_wall,
                                    cdem_error *err) {
    if (!p)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_count_elements: NULL parameters");
    cdem_model m;
    CDEM_TRY(cdem_model_derive(p, &m, err));
    /* the assembly as the run builds it, with the mode's elements (fault ramps, ...) */
    cdem_state st = {0};
    cdem_assembly_info info;
    cdem_bc bc;
    memset(&bc, 0, sizeof bc);
    cdem_status s = cdem_state_init(&st, 1024, 0, err);
    if (s == CDEM_OK)
        s = cdem_assembly_build(p, &m, &st, &info, err);
    int bc_made = 0;
    if (s == CDEM_OK) {
        s = cdem_bc_init(&bc, p, &m, &st, err);
        bc_made = s == CDEM_OK;
    }
    long n_free = 0, n_boundary = 0;
    if (s == CDEM_OK)
        count_kinds(&st, &n_free, &n_boundary);
    if (bc_made)
        cdem_bc_free(&bc);
    cdem_state_free(&st);
    CDEM_TRY(s);
    if (n_internal)
        *n_internal = n_free;
    if (n_wall)
        *n_wall = n_boundary;
    return CDEM_OK;
}
