/* tilt: see tilt.h. The process (solver/process/process.h): active when tilt.angle is not 0;
 * its rules; its summary section (the tilt's history, in model time, in boundary displacement
 * when a boundary moves and in geological time when a process maps the clock); configure (its
 * schedule on the run's model); and its gravity hook, which turns the mode's gravity by the
 * angle of the step. */
#include "bc.h"
#include "process.h"
#include "summary_line.h"
#include "tilt.h"

#include <math.h>
#include <stdio.h>

/* One line of the summary (summary_line.h). */
#define line cdem_summary_line

void cdem_tilt_schedule_of(const cdem_params *p, const cdem_model *m, cdem_tilt_schedule *t) {
    t->angle = p->tilt_angle;
    t->k_run = m->total_steps - m->equil_steps;
    t->k_begin = lround(p->tilt_onset / m->dt);
    if (isnan(p->tilt_duration))
        t->k_end = t->k_run;
    else {
        const long k = lround(p->tilt_duration / m->dt);
        t->k_end = t->k_begin + (k > 1 ? k : 1);
    }
    if (t->k_end <= t->k_begin) /* rest from an onset at the run's end: the rules refuse it */
        t->k_end = t->k_begin + 1;
}

double cdem_tilt_angle_at(const cdem_tilt_schedule *t, long k) {
    if (k <= t->k_begin)
        return 0.0;
    if (k >= t->k_end)
        return t->angle;
    return t->angle * (double)(k - t->k_begin) / (double)(t->k_end - t->k_begin);
}

void cdem_tilt_rules(const cdem_params *p, cdem_rule_log *log) {
    if (p->tilt_angle == 0.0)
        return;
    if (p->sedimentation)
        cdem_rule_add(log,
                      "[tilt] angle = %g with [surface] sedimentation = on: the deposits fill "
                      "to a sea level that is horizontal in the model's frame, which a tilt "
                      "turns away from the horizontal: set one of them off",
                      p->tilt_angle);
    if (p->erosion)
        cdem_rule_add(log,
                      "[tilt] angle = %g with [surface] erosion = on: the erosion level is "
                      "horizontal in the model's frame, which a tilt turns away from the "
                      "horizontal: set one of them off",
                      p->tilt_angle);
    if (p->overburden_pressure > 0.0)
        cdem_rule_add(log,
                      "[tilt] angle = %g with [surface] overburden_pressure = %g N/m: the "
                      "overburden pushes along -y of the model's frame, not along the tilted "
                      "gravity: set one of them to 0",
                      p->tilt_angle, p->overburden_pressure);
    cdem_model m;
    cdem_error err;
    if (cdem_bc_derive_model(p, &m, &err) != CDEM_OK || !(m.dt > 0.0))
        return; /* the table's or the mode's rules say what is wrong */
    if (m.mode.gravity_off) {
        cdem_rule_add(log,
                      "[tilt] angle = %g: the %s mode turns gravity off (%s): a tilt turns "
                      "gravity, so there is nothing to tilt; set [tilt] angle = 0",
                      p->tilt_angle, cdem_mode_name(p->mode), m.mode.gravity_off);
        return;
    }
    if (!(fabs(m.mode.gravity_tilt) + fabs(p->tilt_angle) < 90.0))
        cdem_rule_add(log,
                      "[tilt] angle = %g: with the %s mode's own tilt of %g degrees gravity "
                      "would turn past the horizontal",
                      p->tilt_angle, cdem_mode_name(p->mode), m.mode.gravity_tilt);
    const double run = (double)(m.total_steps - m.equil_steps) * m.dt;
    if (!(p->tilt_onset < run))
        cdem_rule_add(log,
                      "[tilt] onset = %g s: the tilting would begin after the run's %.6g s of "
                      "deformation ([time] runtime - equilibration): lower [tilt] onset or "
                      "raise [time] runtime",
                      p->tilt_onset, run);
    else if (!isnan(p->tilt_duration) && p->tilt_onset + p->tilt_duration > run + 0.5 * m.dt)
        cdem_rule_add(log,
                      "[tilt] onset + duration = %g + %g s: the tilting would end after the "
                      "run's %.6g s of deformation ([time] runtime - equilibration): shorten "
                      "[tilt] duration (rest: to the run's end) or raise [time] runtime",
                      p->tilt_onset, p->tilt_duration, run);
}

typedef struct {
    cdem_tilt_schedule schedule;
} tilt_ctx;

static int tilt_active(const cdem_params *p) {
    return p->tilt_angle != 0.0;
}

/* The tilt's history as the summary states it: its model, its window in model time (and in
 * boundary displacement, geological time), its rate and the gravity it ends with. */
static void tilt_describe(const cdem_params *p, const cdem_model *m, FILE *f) {
    cdem_tilt_schedule t;
    cdem_tilt_schedule_of(p, m, &t);
    const double t0 = (double)t.k_begin * m->dt, t1 = (double)t.k_end * m->dt;
    const double run = (double)t.k_run * m->dt;
    fprintf(f, "\nRegional tilt\n");
    line(f, "model",
         "the whole model (box and base) rotates rigidly relative to gravity: gravity turns in "
         "the model's frame (a tilting table)");
    line(f, "angle",
         "%g degrees: the margin comes to dip toward %s (gravity turns from -y toward %s)",
         fabs(t.angle), t.angle > 0.0 ? "+x" : "-x", t.angle > 0.0 ? "+x" : "-x");
    line(f, "history",
         "untilted to %.6g s after equilibration, tilting at %.4g degrees/s to %.6g s "
         "(deformation steps %ld to %ld), then held to the end (%.6g s)",
         t0, t.angle / (t1 - t0), t1, t.k_begin, t.k_end, run);
    const double v = m->boundary_speed * (double)m->mode.moving_boundaries;
    if (v > 0.0)
        line(f, "in boundary displacement", "tilting from %.6g m to %.6g m (of %.6g m)", v * t0,
             v * t1, v * run);
    const char *by = NULL;
    const double scale = cdem_processes_time_scale(p, m, &by);
    if (scale > 0.0) {
        const double myr = scale / CDEM_SECONDS_PER_YEAR / 1e6;
        line(f, "in geological time", "%.4g Myr of tilting: %.4g degrees/Myr (%s time scale)",
             (t1 - t0) * myr, fabs(t.angle) / ((t1 - t0) * myr), by);
    }
    double gx, gy;
    cdem_model_gravity_vector(m->gravity, m->mode.gravity_tilt + t.angle, &gx, &gy);
    line(f, "gravity at the end", "(%.6g, %.6g) m/s^2, %g degrees from -y", gx, gy,
         m->mode.gravity_tilt + t.angle);
}

static cdem_status tilt_configure(void *ctx, const cdem_params *p, const cdem_model *m,
                                  cdem_integrator *it, cdem_error *err) {
    (void)it, (void)err;
    cdem_tilt_schedule_of(p, m, &((tilt_ctx *)ctx)->schedule);
    return CDEM_OK;
}

/* Turns (*gx, *gy) by the step's angle toward +x: the rotation that takes (0, -g) to
 * (g sin a, -g cos a), as cdem_model_gravity_vector tilts it. */
static void tilt_gravity(const void *ctx, long k, double *gx, double *gy) {
    const double a = cdem_tilt_angle_at(&((const tilt_ctx *)ctx)->schedule, k);
    if (a == 0.0)
        return;
    const double r = a * M_PI / 180.0, c = cos(r), s = sin(r);
    const double x = *gx, y = *gy;
    *gx = x * c - y * s;
    *gy = y * c + x * s;
}

static const cdem_process_ops tilt_ops = {
    .word = "tilt",
    .state_size = sizeof(tilt_ctx),
    .active = tilt_active,
    .rules = cdem_tilt_rules,
    .describe = tilt_describe,
    .configure = tilt_configure,
    .gravity = tilt_gravity,
};

const cdem_process_ops *const cdem_process_tilt = &tilt_ops;
