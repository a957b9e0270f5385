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
 * Progress goes to opt->log only (never stdout); the wall clock is read for the progress
 * display and the thread governor, never for results. This file holds the set-up, the loop and
 * the two ways in (cdem_run, cdem_run_resume); the increments and samples are run_output.c,
 * the progress display run_progress.c, the checkpoints run_ckpt.c (run_ctx.h). */
#include "run_ctx.h"

#include "checkpoint.h"
#include "grid.h"
#include "stress.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* 24 pre-growth layers of equal thickness between the lowest and highest free-element
 * centres at the end of equilibration; layer 1 at the bottom; walls keep layer 0. */
static void assign_layers(cdem_state *s) {
    double lo, hi;
    cdem_state_free_y_range(s, &lo, &hi);
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

/* End of equilibration: the erosion level is erosion_base_level x the height of the
 * equilibrated assembly, measured from the lowest free-element centre to the highest one
 * (the span of the 24 layers): y = lo + level (hi - lo). */
/* End of equilibration: an assembly still sinking will go on compacting under the faulting,
 * which then reads as subsidence everywhere. It settles at the speed its damping allows, so
 * a tall or finely resolved assembly needs longer than cdem's 400 s (examples/inversion: 130
 * elements tall at 125 m, 2500 s). Warned when the free elements' mean downward speed would
 * move them by more than an average radius in another equilibration's time (400 s at
 * least, cdem's default). */
static void warn_if_still_settling(run_ctx *r) {
    double sum_vy = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < r->s.n; i++) {
        if (r->s.flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        sum_vy += r->s.vy[i];
        n++;
    }
    if (n == 0 || !run_logging(r))
        return;
    const double sinking = -sum_vy / (double)n;
    const double horizon = fmax(r->p->equilibration, 400.0); /* cdem's default at least */
    const double more = sinking * horizon;
    if (sinking > 0.0 && more > r->m.average_radius)
        fprintf(r->opt->log,
                "cdem-run: warning: the assembly is still settling at the end of equilibration: "
                "its free elements sink at %.3g m/s on average, %.3g m in another %g s (%.3g "
                "average radii); a longer time.equilibration lets it come to rest before the "
                "boundaries move (docs/guide.md, section 4, \"Equilibration\")\n",
                sinking, more, horizon, more / r->m.average_radius);
}

static void set_erosion_level(run_ctx *r) {
    r->erosion_y = INFINITY;
    if (!r->p->erosion)
        return;
    double lo, hi;
    cdem_state_free_y_range(&r->s, &lo, &hi);
    if (hi >= lo)
        r->erosion_y = lo + r->p->erosion_base_level * (hi - lo);
}

static void log_removed(run_ctx *r) {
    if (r->it.removal.n_removed_last == 0)
        return;
    r->removed += (long)r->it.removal.n_removed_last;
    if (!run_logging(r))
        return;
    run_end_progress_line(r);
    for (size_t k = 0; k < r->it.removal.n_removed_last; k++)
        fprintf(r->opt->log,
                "cdem-run: removed escaping element id %d at step %ld (%ld removed so far)\n",
                (int)r->it.removal.removed_ids[k], r->step, r->removed);
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

/* The stepper's gravity_turn (integrate.h): the run's processes' gravity hooks (process.h). */
static int processes_gravity(const void *procs, long k, double *gx, double *gy) {
    return cdem_processes_gravity(procs, k, gx, gy);
}

/* Everything before the first step, for a fresh run and a resumed one alike: the model, the
 * assembly (regenerated from the seed), the mode, the stepper and the summary. No file yet. */
static cdem_status setup(run_ctx *r, cdem_error *err) {
    const cdem_params *p = r->p;
    const cdem_run_options *opt = r->opt;
    CDEM_TRY(cdem_bc_derive_model(p, &r->m, err));
    CDEM_TRY(run_check_model_memory(&r->m, err)); /* before anything of its size is built */
    if (r->opt->dt_factor > 0.0)
        r->m.dt *= r->opt->dt_factor; /* fault injection (tests): a time step too large */
    CDEM_TRY(cdem_sediment_init(&r->sed, p, &r->m, err));
    CDEM_TRY(cdem_state_init(&r->s, 1024, p->calculate_stress, err));
    CDEM_TRY(cdem_assembly_build(p, &r->m, &r->s, &r->info, err));
    long n_weak = 0;
    CDEM_TRY(cdem_contact_assign_weak(p, &r->s, &n_weak, err));
    if (run_logging(r) && p->weak_interval != CDEM_WEAK_OFF)
        fprintf(opt->log, "cdem-run: weak/light interval: %ld elements flagged weak\n", n_weak);
    CDEM_TRY(cdem_processes_init(&r->procs, p, err));
    CDEM_TRY(
        cdem_processes_place(&r->procs, p, &r->m, &r->s, run_logging(r) ? opt->log : NULL, err));
    r->erosion_y = INFINITY;
    /* the base: wall elements within half a radius of the lowest; the lateral walls' sides:
     * halfway between the outermost wall elements (walls only ever move inward, never past
     * the middle) */
    double ywall = INFINITY, xlo = INFINITY, xhi = -INFINITY;
    for (size_t i = 0; i < r->s.n; i++)
        if (r->s.flags[i] & CDEM_FLAG_WALL) {
            ywall = fmin(ywall, r->s.y[i]);
            xlo = fmin(xlo, r->s.x[i]);
            xhi = fmax(xhi, r->s.x[i]);
        }
    r->base_tol_y = ywall + 0.5 * r->m.radius[0];
    r->wall_mid_x = 0.5 * (xlo + xhi);
    CDEM_TRY(cdem_bc_init(&r->bc, p, &r->m, &r->s, err));
    CDEM_TRY(cdem_integrator_init(&r->it, p, &r->m, err));
    CDEM_TRY(cdem_processes_configure(&r->procs, p, &r->m, &r->it, err));
    r->it.gravity_turn = processes_gravity; /* a process may turn the frame (a tilting margin) */
    r->it.gravity_turn_ctx = &r->procs;
    r->it.unstable_guard = 1;    /* check_unstable */
    r->ckpt.boundary_forces = 1; /* the forces of the first evaluation are current */
    r->it.equilibrating = 1;     /* the packing phase's law until the end of equilibration */
    if (opt->par_min > 0)
        r->it.par_min = opt->par_min;
    cdem_integrator_enable_escape(&r->it);
    CDEM_TRY(cdem_loads_set_overburden(&r->it.loads, p->overburden_pressure, err));
    CDEM_TRY(cdem_loads_set_confining(&r->it.loads, cdem_bc_lateral_pressure(&r->bc),
                                      r->m.equil_steps, r->it.step, err));
    CDEM_TRY(run_make_summary(r, err));
    size_t len = 0;
    FILE *f = open_memstream(&r->ckpt.params_eff, &len);
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the parameter text");
    cdem_params_write_record(p, f);
    fclose(f);
    r->prog.t_start = r->prog.t_last_log = r->prog.t_mark = run_now();
    r->last_written_step = -1;
    return CDEM_OK;
}

/* A fresh run: creates the file, computes the first forces, writes increment 0. */
static cdem_status start_fresh(run_ctx *r, cdem_error *err) {
    const cdem_run_meta meta = {
        .params = r->p,
        .params_text = r->opt->params_text,
        .summary = r->summary,
        .program_version = CDEM_VERSION,
        .source = "cdem-run",
        /* every scheduled increment, and one more written when a run stops between them
         * (a resume drops it again) */
        .max_increments = (long)r->m.n_increments_total + 2,
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
        if (cdem_h5_writer_kept_aside(r->w) && run_logging(r))
            fprintf(r->opt->log,
                    "cdem-run: the completed run %s held is kept as %s until this run completes\n",
                    r->opt->output_path, cdem_h5_writer_kept_aside(r->w));
    }
    r->step = 0;
    r->next_inc = 0;
    CDEM_TRY(cdem_integrator_prime(&r->it, &r->s, err));
    cdem_integrator_mark_initial(&r->it, &r->s);
    log_removed(r);
    CDEM_TRY(run_write_increment(r, err));
    CDEM_TRY(run_write_sample(r, err));
    r->next_inc_step = cdem_model_increment_step(&r->m, r->next_inc);
    return CDEM_OK;
}

/* The first change of the thread count is logged (later ones only counted: a machine whose
 * load comes and goes would fill the log); the last line of the log sums them up. */
static void log_thread_change(run_ctx *r, long step) {
    if (r->gov.changes != 1 || !run_logging(r))
        return;
    run_end_progress_line(r);
    fprintf(r->opt->log,
            "cdem-run: step %ld: 1 thread runs faster than %d now (" GOVERNOR_WHY_ONE
            "); the run goes on with 1 and measures again from time to time (results are the "
            "same for any thread count)\n",
            step, r->gov.allowed);
}

static cdem_status run_loop(run_ctx *r, long until, cdem_error *err) {
    const cdem_params *p = r->p;
    const cdem_run_options *opt = r->opt;
    const long total = r->m.total_steps;
    const long equil = r->m.equil_steps;
    const long interval = p->series_interval > 0 ? p->series_interval : 1;
    if (!r->gov_started) {
        cdem_governor_init(&r->gov, run_now(), r->step);
        r->gov_started = 1;
    }
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
            if (nrem > 0 && run_logging(r)) {
                run_end_progress_line(r);
                fprintf(opt->log,
                        "cdem-run: start of deformation: %zu boundary elements removed by the %s "
                        "mode, %zu elements left\n",
                        nrem, r->bc.name, r->s.n);
            }
        }
        /* the forces on boundary elements count as reported on the steps whose sample reports
         * them, and on every equilibration step of a mode that moves boundaries then (biaxial
         * servo platens); a checkpoint after another step stores them as 0 (boundary_forces) */
        const int eq_moves = step <= equil && cdem_bc_moves_in_equilibration(&r->bc);
        /* the packing phase's law (settling friction) up to the end of equilibration; the
         * damping of deformation steps (physics.deformation_damping) */
        r->it.equilibrating = step <= equil;
        r->it.damping_factor = !deforming                                ? 1.0
                               : p->damping_mode == CDEM_DAMPING_CONTACT ? 0.0
                                                                         : p->deformation_damping;
        r->ckpt.boundary_forces = (step % interval == 0) || eq_moves;
        /* the governor's windows time the stepping alone, not the writes below (governor.h) */
        const int timed = cdem_governor_times_steps(&r->gov);
        const double t_before = timed ? run_now() : 0.0;
        cdem_status st =
            cdem_integrator_step(&r->it, &r->s, (deforming || eq_moves) ? &r->bc : NULL,
                                 deforming ? r->k_def : 0, r->m.displacement_per_step, err);
        if (st != CDEM_OK)
            return st;
        r->step = step;
        const double now = timed || cdem_governor_wants_clock(&r->gov, step) ? run_now() : -1.0;
        if (cdem_governor_after_step(&r->gov, step, now, timed ? now - t_before : -1.0))
            log_thread_change(r, step);
        CDEM_TRY(check_unstable(r, err));
        log_removed(r);
        if (step == equil) {
            assign_layers(&r->s);
            cdem_integrator_classify(&r->it, &r->s);
            set_erosion_level(r);
            cdem_sediment_begin(&r->sed, &r->s);
            long made = cdem_integrator_make_cohesive(&r->it, &r->s);
            run_end_progress_line(r); /* on a terminal the line is kept above the progress line */
            if (run_logging(r))
                fprintf(opt->log, "cdem-run: end of equilibration at step %ld: %ld %s created\n",
                        step, made,
                        p->material == CDEM_MATERIAL_BONDED ? "bonds" : "cohesive contacts");
            warn_if_still_settling(r);
        }
        const long settled = cdem_sediment_after_step(&r->sed, &r->it, &r->s, step);
        if (settled > 0 && run_logging(r)) {
            run_end_progress_line(r);
            fprintf(opt->log, "cdem-run: end of settling at step %ld: %ld %s created\n", step,
                    settled, p->material == CDEM_MATERIAL_BONDED ? "bonds" : "cohesive contacts");
        }
        if (step % interval == 0)
            CDEM_TRY(run_write_sample(r, err));
        while (r->next_inc <= r->m.n_increments_total && step >= r->next_inc_step) {
            CDEM_TRY(run_write_increment(r, err));
            r->next_inc_step = cdem_model_increment_step(&r->m, r->next_inc);
        }
        if (cdem_sediment_due(&r->sed, step)) {
            long added = 0;
            CDEM_TRY(cdem_sediment_event(&r->sed, &r->it, &r->s, step, r->next_inc, &added, err));
            if (run_logging(r)) {
                run_end_progress_line(r);
                fprintf(opt->log,
                        "cdem-run: sedimentation at step %ld: %ld growth elements (layer %d) "
                        "below sea level %.6g m, settling %ld steps\n",
                        step, added, (int)r->sed.settling_layer,
                        cdem_sediment_sea_level(&r->sed, step), r->sed.settling_steps);
            }
        }
        /* checkpoint: after the whole step (deposit included) that wrote an increment, every
         * checkpoint_interval increments; reading the state only, it never changes results */
        if (r->w && !r->ckpt.off && p->checkpoint_interval > 0 && r->last_written_step == step &&
            step < total && r->next_inc - 1 - r->ckpt.last_inc >= p->checkpoint_interval)
            CDEM_TRY(run_write_checkpoint(r, 1, err));
        r->prog.element_steps += (double)r->s.n;
        if (step % 64 == 0)
            run_progress(r, 0);
        /* a stop (signal, max_steps) first checkpoints the state of this step, before the
         * final increment (whose erosion would change it): a resume continues from here and
         * drops that unscheduled increment */
        const int stopping = (opt->stop_requested && *opt->stop_requested) ||
                             (opt->max_steps > 0 && step >= opt->max_steps && step < total);
        if (stopping && r->w && !r->ckpt.off && p->checkpoint_interval > 0 && step < total)
            CDEM_TRY(run_write_checkpoint(r, 0, err));
        if (opt->stop_requested && *opt->stop_requested) {
            if (r->last_written_step != step)
                CDEM_TRY(run_write_increment(r, err));
            char detail[256];
            snprintf(detail, sizeof detail,
                     "stopped by a signal after step %ld of %ld (%s), last increment %d", step,
                     total, run_phase_name(run_phase_of(r, step)), r->next_inc - 1);
            if (r->w)
                CDEM_TRY(cdem_h5_writer_set_stop_reason(r->w, "interrupted", detail, err));
            r->stop_kind = "interrupted";
            char how[CDEM_PATH_MAX + 160];
            run_resume_hint(r, how, sizeof how);
            return CDEM_FAIL(err, CDEM_ERR_INTERRUPTED, "%s; the file %s is valid%s", detail,
                             opt->output_path ? opt->output_path : "(none)", how);
        }
        if (opt->max_steps > 0 && step >= opt->max_steps && step < total) {
            if (r->last_written_step != step)
                CDEM_TRY(run_write_increment(r, err));
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
        CDEM_TRY(run_write_increment(r, err));
    char detail[256];
    snprintf(detail, sizeof detail,
             "%ld steps, %d increments (0..%d), %ld escaping elements removed, %ld eroded", r->step,
             r->next_inc, r->next_inc - 1, r->removed, r->eroded);
    r->finished = 1;
    r->stop_kind = "completed";
    return r->w ? cdem_h5_writer_set_stop_reason(r->w, "completed", detail, err) : CDEM_OK;
}

static void run_release(run_ctx *r) {
    if (r->gov_started)
        cdem_governor_finish(&r->gov);
    cdem_integrator_free(&r->it);
    cdem_processes_free(&r->procs); /* after the stepper, which held their hooks */
    cdem_sediment_free(&r->sed);
    cdem_bc_free(&r->bc);
    cdem_state_free(&r->s);
    cdem_snapshot_free(r->ckpt.snap);
    free(r->summary);
    free(r->ckpt.params_eff);
    free(r);
}

static cdem_status open_body(run_ctx *r, const cdem_snapshot *resume, cdem_error *err) {
    CDEM_TRY(setup(r, err));
    if (!resume)
        return start_fresh(r, err);
    CDEM_TRY(run_restore(r, resume, err));
    if (r->opt->output_path) {
        CDEM_TRY(cdem_h5_writer_reopen(r->opt->output_path, r->next_inc - 1, r->step, &r->w, err));
        cdem_h5_writer_set_sync(r->w, !r->opt->no_fsync);
    }
    if (run_logging(r))
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
            /* A fresh file the run could not start (increment 0 refused, issue 46 item 2)
             * records why: left "running", info called it a killed run to run again. */
            if (!resume && st != CDEM_ERR_INTERRUPTED)
                (void)cdem_h5_writer_set_stop_reason(r->w,
                                                     st == CDEM_ERR_IO ? "write-failure" : "error",
                                                     err ? err->msg : cdem_status_str(st), &e2);
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

cdem_status cdem_run_close(cdem_run_ctx *r, cdem_status st, cdem_error *err) {
    if (!r)
        return st;
    if (run_logging(r)) {
        const char *ending = st == CDEM_OK && r->stop_kind && !strcmp(r->stop_kind, "stopped-early")
                                 ? "stopped early"
                             : st == CDEM_OK              ? "completed"
                             : st == CDEM_ERR_INTERRUPTED ? "interrupted"
                                                          : "failed";
        run_progress_line(r, 1, ending);
        run_end_progress_line(r);
        cdem_processes_finish(&r->procs, r->opt->log);
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
        cdem_h5_close_report rep;
        cdem_status cst = cdem_h5_writer_close_report(r->w, &rep, st == CDEM_OK ? err : &e3);
        if (st == CDEM_OK)
            st = cst;
        r->w = NULL;
        if (rep.note[0] && run_logging(r)) /* the file is complete, only larger */
            fprintf(r->opt->log, "cdem-run: note: %s\n", rep.note);
        if (rep.dropped_replaced && run_logging(r))
            fprintf(r->opt->log, "cdem-run: removed %s.replaced, the run this one replaced\n",
                    r->opt->output_path);
        if (cst == CDEM_OK)
            run_log_wrote(r, st, had_writer);
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

cdem_status cdem_run_count_elements(const cdem_params *p, long *n_internal, long *n_wall,
                                    cdem_error *err) {
    if (!p)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_count_elements: NULL parameters");
    cdem_model m;
    CDEM_TRY(cdem_bc_derive_model(p, &m, err));
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
        run_count_kinds(&st, &n_free, &n_boundary);
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
        st = cdem_run_validate(&p, err);
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
    /* A damaged commit row that held an increment (issue 46): the resumed run must not build
     * on it, so it continues from a checkpoint of an increment before that row (the resume
     * then drops that row and every later one, and writes them again), or not at all. */
    int32_t intact = 0;
    if (st == CDEM_OK && cdem_h5_reader_damaged_increments(rd, &intact) && inc > intact) {
        const int32_t newest = inc;
        cdem_error e2;
        cdem_error_clear(&e2);
        if (intact < 0 ||
            cdem_h5_reader_read_checkpoint_through(rd, snap, intact, &inc, &e2) != CDEM_OK)
            st = CDEM_FAIL(err, CDEM_ERR_FORMAT,
                           "%s: cannot be resumed: its checkpoint belongs to increment %d, after "
                           "a damaged row of its commit record (%s), and no valid checkpoint "
                           "belongs to an increment before that row (%d or earlier; %s): a "
                           "resumed run would build on the damaged row; it was not changed, "
                           "and its valid increments can still be read",
                           path, (int)newest, cdem_h5_reader_damage(rd), (int)intact,
                           intact < 0 ? "no increment precedes it" : e2.msg);
        else if (opt->log)
            fprintf(opt->log,
                    "cdem-run: resuming %s from the checkpoint of increment %d, before its "
                    "damaged commit row (the newest checkpoint, of increment %d, follows that "
                    "row); the increments after %d are written again\n",
                    path, (int)inc, (int)newest, (int)inc);
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
