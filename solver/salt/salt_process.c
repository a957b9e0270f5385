/* salt_process: the salt as a process of the run (solver/process/process.h): its parameter
 * rules (salt_rules.c), its summary section, its placement in the built assembly, its forces
 * in the step (through the viscous module's hooks, step/viscous.h), its elements' stress and
 * its measures at each increment and sample, and the run's last log line about its area.
 * Everything the run knew of the salt by name is here: the run loop, the output and the
 * summary call the process registry. */
#include "process.h"
#include "salt.h"
#include "summary_line.h"
#include "viscous.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* One line of the summary (summary_line.h). */
#define line cdem_summary_line

typedef struct {
    cdem_salt_model model; /* its constants (cdem_salt_model_derive, at placement) */
    cdem_salt_layer layer; /* what the placement measured */
    cdem_salt salt;        /* the module: its grid, pairs and constants (salt.h) */
    double area_change;    /* largest |salt area / its area at placement - 1| over the
                              increments this process wrote (logged at the end) */
} salt_ctx;

static int salt_active(const cdem_params *p) {
    return p->salt_layer != CDEM_SALT_OFF;
}

/* The salt's section (docs/solver.md, section 9): where it is, its material and how the
 * model's clock maps onto geological time, with the ratio that mapping keeps. */
static void salt_describe(const cdem_params *p, const cdem_model *m, FILE *f) {
    cdem_salt_model salt_model;
    cdem_error err;
    if (cdem_salt_model_derive(p, m, &salt_model, &err) != CDEM_OK)
        return; /* the parameter check refuses it first */
    const cdem_salt_model *sm = &salt_model;
    cdem_salt_time t;
    cdem_salt_time_map(p, m, sm, &t);
    fprintf(f, "\nSalt\n");
    if (p->salt_layer == CDEM_SALT_BASAL)
        line(f, "layer",
             "basal, lowest %g %% of the span of element centres = %.6g m (fixed at "
             "assembly)",
             p->salt_thickness_percent, t.salt_thickness);
    else
        line(f, "layer",
             "interval from %g to %g %% of the span of element centres = %.6g m "
             "(fixed at assembly)",
             p->salt_interval_bottom_percent, p->salt_interval_top_percent, t.salt_thickness);
    line(f, "cover above", "%.6g m", t.cover_thickness);
    line(f, "salt density", "%g kg/m^3 (smallest salt mass %.6g kg/m)", sm->density, sm->mass[0]);
    line(f, "viscosity", "%g Pa s geological = %.4g Pa s in the model (/ time scale)",
         sm->viscosity_geological, sm->viscosity);
    if (isnan(p->salt_time_scale))
        line(f, "geological rate", "%g mm/yr = %.4g m/s, shown by the model's %.6g m/s",
             p->salt_rate, sm->rate, m->boundary_speed);
    else /* only without a moving boundary (salt_rules.c refuses it with one: issue 46) */
        line(f, "geological rate", "none: no boundary moves (salt.rate is not used)");
    line(f, "time scale S", "%.4g (1 model s = %.4g yr%s)", sm->time_scale,
         sm->time_scale / CDEM_SECONDS_PER_YEAR,
         isnan(p->salt_time_scale) ? "; boundary speed / geological rate" : "; salt.time_scale");
    line(f, "deformation phase", "%g s of model time = %.4g Myr", p->runtime - p->equilibration,
         t.deformation_yr / 1e6);
    if (isnan(t.pi_ratio))
        line(f, "eta V / (rho g h H)", "none (gravity off)");
    else
        line(f, "eta V / (rho g h H)",
             "%.3g (salt %.6g m, cover %.6g m): the same in model and nature", t.pi_ratio,
             t.salt_thickness, t.cover_thickness);
    line(f, "Reynolds number", "%.3g (rho_s V h / eta in the model; %s)", t.reynolds,
         t.reynolds < 0.1 ? "viscous" : "WARNING: above 0.1, inertia is not negligible");
    line(f, "grid", "%.6g m (%g mean radii), bulk modulus %g Pa", sm->grid_spacing,
         p->salt_grid_spacing, sm->bulk_modulus);
    line(f, "time-step limits", "grid viscosity %.3g s, grid pressure %.3g s (time step %.6g s)",
         t.dt_viscous, t.dt_pressure, m->dt);
    line(f, "damping", "%s (absolute damping would give D = %.3g)",
         p->damping_mode == CDEM_DAMPING_CONTACT ? "contact" : "absolute", t.damping_number);
    line(f, "contacts", "cover %s, base %s, walls %s; salt pairs: no friction, no cohesion",
         p->salt_cover_contact == CDEM_SALT_NO_SLIP ? "no-slip" : "free-slip",
         p->salt_base_contact == CDEM_SALT_NO_SLIP ? "no-slip" : "free-slip",
         p->salt_wall_contact == CDEM_SALT_NO_SLIP ? "no-slip" : "free-slip");
}

static cdem_status salt_place(void *vctx, const cdem_params *p, const cdem_model *m, cdem_state *s,
                              FILE *log, cdem_error *err) {
    salt_ctx *c = vctx;
    CDEM_TRY(cdem_salt_model_derive(p, m, &c->model, err));
    CDEM_TRY(cdem_salt_place(p, m, &c->model, s, &c->layer, err));
    if (log && c->layer.elements > 0)
        fprintf(log,
                "cdem-run: salt: %ld elements between y = %.6g and %.6g m, packing fraction %.4f, "
                "dashpot beta %.4g\n",
                c->layer.elements, c->layer.band_lo, c->layer.band_hi, c->layer.phi, c->layer.beta);
    return CDEM_OK;
}

/* The module's forces in the step (viscous.h) */
static cdem_status salt_after_build(void *vctx, const cdem_neighbour *nb, const cdem_state *s,
                                    cdem_error *err) {
    return cdem_salt_after_build(vctx, nb, s, err);
}

static void salt_forces(void *vctx, const cdem_state *s, double *ex, double *ey) {
    cdem_salt_forces(vctx, s, ex, ey);
}

static void salt_after_step(void *vctx, cdem_state *s, double dt) {
    cdem_salt_project(vctx, s, dt);
}

static const cdem_viscous_hooks salt_hooks = {salt_after_build, salt_forces, salt_after_step};

cdem_status cdem_salt_join(cdem_salt *salt, cdem_viscous *v, cdem_error *err) {
    return salt->on ? cdem_viscous_add(v, &salt_hooks, salt, err) : CDEM_OK;
}

static cdem_status salt_configure(void *vctx, const cdem_params *p, const cdem_model *m,
                                  cdem_integrator *it, cdem_error *err) {
    salt_ctx *c = vctx;
    CDEM_TRY(cdem_salt_configure(&c->salt, m, &c->model, p, &c->layer, it->nb.skin, err));
    return cdem_salt_join(&c->salt, &it->viscous, err);
}

static void salt_increment(void *vctx, cdem_state *s) {
    salt_ctx *c = vctx;
    if (s->has_stress) /* salt elements: their continuum stress (no pair carries theirs) */
        cdem_salt_stress(&c->salt, s);
    if (c->layer.elements > 0 && c->layer.phi > 0.0) {
        double area, top;
        long count;
        cdem_salt_measures(s, c->layer.phi, &area, &top, &count);
        const double change = fabs(area / (c->layer.disc_area / c->layer.phi) - 1.0);
        if (change > c->area_change)
            c->area_change = change;
    }
}

static void salt_sample(const void *vctx, const cdem_state *s, cdem_series_sample *q) {
    const salt_ctx *c = vctx;
    if (c->layer.elements > 0 && c->layer.phi > 0.0) {
        long count;
        cdem_salt_measures(s, c->layer.phi, &q->salt_area, &q->salt_top, &count);
    }
}

static void salt_finish(const void *vctx, FILE *log) {
    const salt_ctx *c = vctx;
    if (log && c->layer.elements > 0)
        fprintf(log,
                "cdem-run: salt: area %.6g m^2 at placement; largest change at an increment "
                "%.3g %%\n",
                c->layer.disc_area / c->layer.phi, 100.0 * c->area_change);
}

static void salt_free(void *vctx) {
    cdem_salt_free(&((salt_ctx *)vctx)->salt);
}

/* The clock's map to geological time (salt.rate or salt.time_scale), 0 when it cannot be
 * derived (the rules say why). */
static double salt_time_scale(const cdem_params *p, const cdem_model *m) {
    cdem_salt_model sm;
    cdem_error err;
    return cdem_salt_model_derive(p, m, &sm, &err) == CDEM_OK ? sm.time_scale : 0.0;
}

static const cdem_process_ops salt_ops = {
    .word = "salt",
    .state_size = sizeof(salt_ctx),
    .flag = CDEM_FLAG_SALT,
    .active = salt_active,
    .rules = cdem_salt_rules,
    .describe = salt_describe,
    .time_scale = salt_time_scale,
    .place = salt_place,
    .configure = salt_configure,
    .increment = salt_increment,
    .sample = salt_sample,
    .finish = salt_finish,
    .free = salt_free,
};

const cdem_process_ops *const cdem_process_salt = &salt_ops;
