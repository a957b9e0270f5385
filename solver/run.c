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
 * ("stopped-early", CDEM_OK). Progress goes to opt->log only (never stdout); the wall clock
 * is read only for the progress display, never for results. */
#include "run.h"

#include "assembly.h"
#include "bc.h"
#include "h5format.h"
#include "integrate.h"
#include "model.h"
#include "sediment.h"
#include "stress.h"
#include "summary.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#ifndef CDEM_VERSION
#define CDEM_VERSION "0.0.0"
#endif

/* Everything a run owns, released by run_free. */
typedef struct {
    const cdem_params *p;        /* parameters (caller's) */
    const cdem_run_options *opt; /* options (caller's) */
    cdem_model m;                /* derived constants */
    cdem_state s;                /* the elements */
    cdem_assembly_info info;     /* what the assembly generator built */
    cdem_bc bc;                  /* boundary mode */
    cdem_integrator it;          /* time stepper */
    cdem_h5_writer *w;           /* output file */
    char *summary;               /* summary + mode view, malloc'd */
    long step;                   /* last completed step */
    int next_inc;                /* number of the next increment to write */
    long last_written_step;      /* step of the last increment written (-1: none) */
    double base_tol_y;           /* m, wall elements with y below this are the base */
    long removed;                /* escaped elements removed */
    long eroded;                 /* elements removed by erosion, whole run */
    double erosion_y;            /* m, erosion level (INFINITY until the end of equilibration) */
    double t_start, t_last_log;  /* s, monotonic clock (progress display only) */
    long last_log_step;          /* step of the last progress output */
    int tty_line_open;           /* 1 when a progress line is drawn without newline */
    cdem_sediment sed;           /* syn-tectonic sedimentation (disabled when off) */
    long k_def;                  /* deformation steps applied by the mode (settling excluded) */
} run_ctx;

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

static void progress(run_ctx *r, int force) {
    if (!logging(r))
        return;
    const double t = now_s();
    const long total = r->m.total_steps;
    const double elapsed = t - r->t_start;
    const double rate = elapsed > 0.0 ? (double)r->step / elapsed : 0.0;
    const double left = rate > 0.0 ? (double)(total - r->step) / rate : 0.0;
    const double net = cdem_bc_net_displacement(&r->bc);
    const int inc_done = r->next_inc - 1;
    if (r->opt->progress_is_tty) {
        if (!force && t - r->t_last_log < 0.25)
            return;
        fprintf(r->opt->log,
                "\r\033[K%s, increment %d/%d, net displacement %.1f m, %zu elements, %.0f "
                "steps/s, %.0f s left",
                phase_name(phase_of(r, r->step)), inc_done, r->m.n_increments_total, net, r->s.n,
                rate, left);
        fflush(r->opt->log);
        r->tty_line_open = 1;
    } else {
        const long tenth = total / 10 > 0 ? total / 10 : 1;
        if (!force && r->step - r->last_log_step < tenth && t - r->t_last_log < 30.0)
            return;
        fprintf(r->opt->log,
                "cdem-run: %s, step %ld/%ld, increment %d/%d, net displacement %.1f m, %zu "
                "elements, %.0f steps/s, %.0f s left\n",
                phase_name(phase_of(r, r->step)), r->step, total, inc_done, r->m.n_increments_total,
                net, r->s.n, rate, left);
        fflush(r->opt->log);
        r->last_log_step = r->step;
    }
    r->t_last_log = t;
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
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY) {
            s->layer[i] = 0;
            continue;
        }
        long k = (long)floor((s->y[i] - lo) / th) + 1;
        if (k < 1)
            k = 1;
        if (k > CDEM_PREGROWTH_LAYERS)
            k = CDEM_PREGROWTH_LAYERS;
        s->layer[i] = (int32_t)k;
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
    return cdem_h5_writer_append_series(r->w, &q, err);
}

static cdem_status make_summary(run_ctx *r, cdem_error *err) {
    char *text = NULL;
    CDEM_TRY(cdem_summary_text(r->p, &r->m, r->info.n_internal, r->info.n_wall, 0, &text, err));
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
 * still finite (the escaping elements are removed and the run would go on). Serial and in
 * index order, so the element reported is the same for any thread count. */
static cdem_status check_unstable(const run_ctx *r, cdem_error *err) {
    const cdem_state *s = &r->s;
    const double dt = r->m.dt;
    for (size_t i = 0; i < s->n; i++) {
        const double d2 = (s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i]) * dt * dt;
        if (d2 > s->radius[i] * s->radius[i])
            return CDEM_FAIL(err, CDEM_ERR_NUMERIC,
                             "element id %d moved %.3g m in one time step (more than its radius "
                             "%.3g m) at step %ld: the simulation is unstable; likely cause: the "
                             "time step is too large for the spring constants and element masses",
                             (int)s->id[i], sqrt(d2), s->radius[i], r->step);
    }
    return CDEM_OK;
}

static cdem_status run_body(run_ctx *r, cdem_error *err) {
    const cdem_params *p = r->p;
    const cdem_run_options *opt = r->opt;
    CDEM_TRY(cdem_model_derive(p, &r->m, err));
    if (opt->dt_factor > 0.0)
        r->m.dt *= opt->dt_factor; /* fault injection (tests): a time step too large */
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
    cdem_integrator_enable_escape(&r->it);
    CDEM_TRY(cdem_integrator_set_overburden(&r->it, p->overburden_pressure, err));
    CDEM_TRY(cdem_integrator_set_confining(&r->it, cdem_bc_lateral_pressure(&r->bc),
                                           r->m.equil_steps, err));
    CDEM_TRY(make_summary(r, err));
    const cdem_run_meta meta = {
        .params = p,
        .params_text = opt->params_text,
        .summary = r->summary,
        .program_version = CDEM_VERSION,
        .source = "cdem-run",
    };
    CDEM_TRY(cdem_h5_writer_create(opt->output_path, &meta, &r->w, err));

    r->t_start = r->t_last_log = now_s();
    r->step = 0;
    r->next_inc = 0;
    r->last_written_step = -1;
    CDEM_TRY(cdem_integrator_prime(&r->it, &r->s, err));
    log_removed(r);
    CDEM_TRY(write_increment(r, err));
    CDEM_TRY(write_sample(r, err));

    const long total = r->m.total_steps;
    const long equil = r->m.equil_steps;
    const long interval = p->series_interval > 0 ? p->series_interval : 1;
    long next_inc_step = cdem_model_increment_step(&r->m, r->next_inc);
    while (r->step < total) {
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
        /* wall forces are summed only on the steps whose sample reports them */
        r->it.boundary_forces = (step % interval == 0);
        cdem_status st = cdem_integrator_step(&r->it, &r->s, deforming ? &r->bc : NULL, r->k_def,
                                              r->m.displacement_per_step, err);
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
            if (logging(r) && !opt->progress_is_tty)
                fprintf(opt->log, "cdem-run: end of equilibration at step %ld: %ld %s created\n",
                        step, made,
                        p->material == CDEM_MATERIAL_BONDED ? "bonds" : "cohesive contacts");
        }
        const long settled = cdem_sediment_after_step(&r->sed, &r->it, &r->s, step);
        if (settled > 0 && logging(r) && !opt->progress_is_tty)
            fprintf(opt->log, "cdem-run: end of settling at step %ld: %ld %s created\n", step,
                    settled, p->material == CDEM_MATERIAL_BONDED ? "bonds" : "cohesive contacts");
        if (step % interval == 0)
            CDEM_TRY(write_sample(r, err));
        while (r->next_inc <= r->m.n_increments_total && step >= next_inc_step) {
            CDEM_TRY(write_increment(r, err));
            next_inc_step = cdem_model_increment_step(&r->m, r->next_inc);
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
        if (step % 64 == 0)
            progress(r, 0);
        if (opt->stop_requested && *opt->stop_requested) {
            if (r->last_written_step != step)
                CDEM_TRY(write_increment(r, err));
            char detail[256];
            snprintf(detail, sizeof detail,
                     "stopped by a signal after step %ld of %ld (%s), last increment %d", step,
                     total, phase_name(phase_of(r, step)), r->next_inc - 1);
            CDEM_TRY(cdem_h5_writer_set_stop_reason(r->w, "interrupted", detail, err));
            return CDEM_FAIL(err, CDEM_ERR_INTERRUPTED, "%s; the file %s is valid", detail,
                             opt->output_path);
        }
        if (opt->max_steps > 0 && step >= opt->max_steps && step < total) {
            if (r->last_written_step != step)
                CDEM_TRY(write_increment(r, err));
            char detail[256];
            snprintf(detail, sizeof detail, "max_steps = %ld reached at step %ld of %ld",
                     opt->max_steps, step, total);
            CDEM_TRY(cdem_h5_writer_set_stop_reason(r->w, "stopped-early", detail, err));
            return CDEM_OK;
        }
    }
    if (r->last_written_step != r->step)
        CDEM_TRY(write_increment(r, err));
    char detail[256];
    snprintf(detail, sizeof detail,
             "%ld steps, %d increments, %ld escaping elements removed, %ld eroded", r->step,
             r->next_inc - 1, r->removed, r->eroded);
    return cdem_h5_writer_set_stop_reason(r->w, "completed", detail, err);
}

cdem_status cdem_run(const cdem_params *p, const cdem_run_options *opt, cdem_error *err) {
    if (!p || !opt || !opt->output_path)
        return CDEM_FAIL(err, CDEM_ERR_INVALID,
                         "cdem_run: parameters, options and an output path are required");
    run_ctx r;
    memset(&r, 0, sizeof r);
    r.p = p;
    r.opt = opt;
    cdem_status st = run_body(&r, err);
    if (logging(&r)) {
        progress(&r, 1);
        end_progress_line(&r);
    }
    if (r.w) {
        if (st == CDEM_ERR_NUMERIC && err) {
            /* the numbers behind "time step too large": what a user can change */
            size_t len = strlen(err->msg);
            snprintf(err->msg + len, sizeof err->msg - len,
                     " (time step %g s, spring constant %g N/m, smallest element mass %g kg per "
                     "metre%s)",
                     r.m.dt, r.m.kn, r.m.min_mass,
                     p->keep_constants && p->unit_scaling < 1000.0
                         ? "; keep_constants = on keeps the 1000 m spring and damping constants "
                           "at this smaller unit_scaling: try keep_constants = off"
                         : "");
        }
        if (st != CDEM_OK && st != CDEM_ERR_INTERRUPTED) {
            /* record the diagnosis in the file; keep the original error */
            cdem_error e2;
            cdem_error_clear(&e2);
            (void)cdem_h5_writer_set_stop_reason(
                r.w, st == CDEM_ERR_NUMERIC ? "numerical-failure" : "error",
                err ? err->msg : cdem_status_str(st), &e2);
        }
        cdem_error e3;
        cdem_error_clear(&e3);
        cdem_status cst = cdem_h5_writer_close(r.w, st == CDEM_OK ? err : &e3);
        if (st == CDEM_OK)
            st = cst;
    }
    cdem_integrator_free(&r.it);
    cdem_sediment_free(&r.sed);
    cdem_bc_free(&r.bc);
    cdem_state_free(&r.s);
    free(r.summary);
    return st;
}

cdem_status cdem_run_count_elements(const cdem_params *p, long *n_internal, long *n_wall,
                                    cdem_error *err) {
    if (!p)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_count_elements: NULL parameters");
    cdem_model m;
    CDEM_TRY(cdem_model_derive(p, &m, err));
    return cdem_assembly_count(p, &m, n_internal, n_wall, err);
}
