/* salt_rules: the parameter rules of the salt (salt.h, cdem_salt_rules), added to cdem-run's
 * validation (solver/run/run_validate.c): one line a violated rule, each naming the keys to
 * change; and the time mapping they and the summary share (cdem_salt_time_map). The numbers behind
 * them (docs/solver.md, "Salt"):
 *  - the damping number D = (c_abs / (pi r^2)) H_c h_s / eta_m: how much more the paper's
 *    absolute damping (a drag on each element's velocity) resists a cover of thickness H_c
 *    moving over salt of thickness h_s than the salt's viscous traction does. It does not
 *    depend on the time scale; 138 in the worked example, so salt needs contact damping;
 *  - the explicit limits of the salt's grid: viscous rho phi h^2 / (8 eta_m) and pressure
 *    0.25 sqrt(m / k), k = 1.5 K A^2 / (phi h^4), both above the time step (the integration
 *    has no sub-steps). phi is not known before the assembly; the check uses 0.75, below the
 *    packings the assembly makes (0.80-0.84), so it errs on the safe side. */
#include "salt.h"

#include "bc.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *layer_word(cdem_salt_layer_choice c) {
    return c == CDEM_SALT_BASAL ? "basal" : c == CDEM_SALT_INTERVAL ? "interval" : "off";
}

/* The salt's band and the weak interval's, as fractions of the span of centres. */
static void salt_band(const cdem_params *p, double *a, double *b) {
    if (p->salt_layer == CDEM_SALT_BASAL) {
        *a = 0.0;
        *b = p->salt_thickness_percent / 100.0;
    } else {
        *a = p->salt_interval_bottom_percent / 100.0;
        *b = p->salt_interval_top_percent / 100.0;
    }
}

void cdem_salt_time_map(const cdem_params *p, const cdem_model *m, const cdem_salt_model *sm,
                        cdem_salt_time *t) {
    memset(t, 0, sizeof *t);
    if (p->salt_layer == CDEM_SALT_OFF || !sm->on)
        return;
    double a, b;
    salt_band(p, &a, &b);
    t->salt_thickness = (b - a) * m->height_m;
    t->cover_thickness = (1.0 - b) * m->height_m;
    t->time_scale = sm->time_scale;
    t->viscosity_model = sm->viscosity;
    t->boundary_speed = m->boundary_speed;
    t->rate = sm->rate;
    const double hs = t->salt_thickness, hc = t->cover_thickness;
    t->pi_ratio = m->gravity > 0.0 && hc > 0.0
                      ? sm->viscosity * m->boundary_speed / (p->density * m->gravity * hs * hc)
                      : NAN;
    t->reynolds = sm->density * m->boundary_speed * hs / sm->viscosity;
    const double r = m->average_radius;
    t->damping_number = m->damping / (M_PI * r * r) * hc * hs / sm->viscosity;
    const double h = sm->grid_spacing, phi = CDEM_SALT_RULES_PHI;
    t->dt_viscous = sm->density * phi * h * h / (8.0 * sm->viscosity);
    const double area = M_PI * m->radius[0] * m->radius[0] / phi;
    const double k = 1.5 * sm->bulk_modulus * area * area / (phi * pow(h, 4.0));
    t->dt_pressure = 0.25 * sqrt(sm->mass[0] / k);
    t->deformation_yr = (p->runtime - p->equilibration) * sm->time_scale / CDEM_SECONDS_PER_YEAR;
}

/* An explicit salt.time_scale with a moving boundary (issue 46, item 4): it overrode salt.rate
 * silently (the summary showed "5 mm/yr" beside a time scale that meant 0.02 mm/yr). With a
 * moving boundary the time scale is the rate's, S = boundary speed / rate: the pair is
 * refused, naming the rate the time scale stands for and, when the table allows it, the rate
 * that gives that time scale. */
static void time_scale_rule(const cdem_params *p, const cdem_model *m, cdem_rule_log *log) {
    char ts[64], rate[64], implied[64], range[200];
    const double mm_yr = 1e3 * CDEM_SECONDS_PER_YEAR; /* m/s -> mm/yr */
    const double v = m->boundary_speed, r = v / p->salt_time_scale * mm_yr;
    cdem_params_format_number(p->salt_time_scale, ts, sizeof ts);
    cdem_params_format_number(p->salt_rate, rate, sizeof rate);
    snprintf(implied, sizeof implied, "%.4g", r);
    const cdem_param_def *d = cdem_params_find("salt", "rate");
    if (d && r >= d->min && r <= d->max)
        snprintf(range, sizeof range, "; for this time scale set salt.rate = %s mm/yr", implied);
    else if (d)
        snprintf(range, sizeof range,
                 "; no salt.rate gives this time scale (%g to %g mm/yr give S = %.4g to %.4g)",
                 d->min, d->max, v / (d->max / mm_yr), v / (d->min / mm_yr));
    else
        range[0] = '\0';
    cdem_rule_add(log,
                  "salt.time_scale = %s with boundary.mode = %s, whose boundary moves: the time "
                  "scale follows from salt.rate = %s mm/yr (S = boundary speed %.4g m/s / rate "
                  "= %.4g), and this one would override it (it stands for %s mm/yr): set "
                  "salt.time_scale = rate (a time scale of its own is for modes without a "
                  "moving boundary)%s",
                  ts, cdem_mode_name(p->mode), rate, v, v / (p->salt_rate / mm_yr), implied, range);
}

void cdem_salt_rules(const cdem_params *p, cdem_rule_log *log) {
    if (p->salt_layer == CDEM_SALT_OFF)
        return;
    const char *lw = layer_word(p->salt_layer);
    char v1[64], v2[64];
    if (p->material == CDEM_MATERIAL_BONDED)
        cdem_rule_add(log,
                      "salt.layer = %s: not supported with material.material = bonded (a bonded "
                      "cover over salt is not calibrated): set material.material = granular or "
                      "salt.layer = off",
                      lw);
    if (cdem_bc_excludes(p->mode, CDEM_EXCLUDES_PROCESSES))
        cdem_rule_add(log,
                      "salt.layer = %s: not supported with boundary.mode = %s (a test of the "
                      "cover's material): set salt.layer = off",
                      lw, cdem_mode_name(p->mode));
    double a, b;
    salt_band(p, &a, &b);
    if (p->salt_layer == CDEM_SALT_INTERVAL && !(a < b)) {
        cdem_params_format_number(p->salt_interval_bottom_percent, v1, sizeof v1);
        cdem_params_format_number(p->salt_interval_top_percent, v2, sizeof v2);
        cdem_rule_add(log,
                      "salt.interval_bottom_percent = %s must be below salt.interval_top_percent "
                      "= %s",
                      v1, v2);
    }
    if (p->salt_layer == CDEM_SALT_INTERVAL && a <= 0.0 && b >= 1.0) {
        /* every free element's centre lies in the band: the placement would refuse it (issue
         * 46, item 3: the summary showed "cover above: 0 m", the run refused) */
        cdem_params_format_number(p->salt_interval_bottom_percent, v1, sizeof v1);
        cdem_params_format_number(p->salt_interval_top_percent, v2, sizeof v2);
        cdem_rule_add(log,
                      "salt.layer = interval: the salt's band, salt.interval_bottom_percent = %s "
                      "to salt.interval_top_percent = %s %% of the span of element centres, "
                      "holds every element: make it thinner (the salt must leave a cover): "
                      "raise salt.interval_bottom_percent or lower salt.interval_top_percent",
                      v1, v2);
    }
    if (p->weak_interval != CDEM_WEAK_OFF) {
        const double t = p->weak_thickness_percent / 100.0;
        const double wa = p->weak_interval == CDEM_WEAK_LOWER ? 0.0 : 1.0 - t;
        const double wb = p->weak_interval == CDEM_WEAK_LOWER ? t : 1.0;
        if (t > 0.0 && a < wb && wa < b)
            cdem_rule_add(log,
                          "salt.layer = %s conflicts with heterogeneity.weak_interval = %s (both "
                          "claim %s of the assembly): move or thin one of them, or set "
                          "heterogeneity.weak_interval = off",
                          lw, p->weak_interval == CDEM_WEAK_LOWER ? "lower" : "upper",
                          p->weak_interval == CDEM_WEAK_LOWER ? "the lower part" : "the top");
    }
    cdem_model m;
    cdem_salt_model salt_model;
    cdem_error err;
    if (cdem_bc_derive_model(p, &m, &err) != CDEM_OK ||
        cdem_salt_model_derive(p, &m, &salt_model, &err) != CDEM_OK)
        return; /* the table's rules or the mode's say what is wrong */
    const cdem_salt_model *sm = &salt_model;
    const int own_scale = !isnan(p->salt_time_scale);
    if (own_scale && m.mode.moving_boundaries > 0)
        time_scale_rule(p, &m, log);
    cdem_salt_time t;
    cdem_salt_time_map(p, &m, sm, &t);
    if (p->damping_mode == CDEM_DAMPING_ABSOLUTE) {
        const double D = t.damping_number;
        if (!(D < 0.1))
            cdem_rule_add(log,
                          "salt.layer = %s with physics.damping_mode = absolute: the damping "
                          "would resist the cover's motion over the salt %.3g times more than "
                          "the salt does (damping number D = %.3g, must be < 0.1): set "
                          "physics.damping_mode = contact",
                          lw, D, D);
    }
    const double dt_viscous = t.dt_viscous, dt_pressure = t.dt_pressure;
    cdem_params_format_number(p->salt_viscosity, v1, sizeof v1);
    cdem_params_format_number(own_scale ? p->salt_time_scale : p->salt_rate, v2, sizeof v2);
    /* the model's viscosity is viscosity / S, S = boundary speed / rate: a lower rate or a
     * larger S makes it less viscous (the advice said "raise salt.rate", which made it worse) */
    if (!(m.dt < dt_viscous))
        cdem_rule_add(log,
                      "salt.viscosity = %s Pa s at %s = %s%s is %.4g Pa s in the model, too "
                      "viscous for its grid: the explicit limit rho phi h^2 / (8 eta) = %.3g s "
                      "is below the time step %.3g s (the integration has no sub-steps): lower "
                      "salt.viscosity, %s or raise salt.grid_spacing",
                      v1, own_scale ? "salt.time_scale" : "salt.rate", v2,
                      own_scale ? "" : " mm/yr", sm->viscosity, dt_viscous, m.dt,
                      own_scale ? "raise salt.time_scale" : "lower salt.rate");
    if (!(m.dt < dt_pressure)) {
        cdem_params_format_number(p->salt_bulk_modulus, v1, sizeof v1);
        cdem_rule_add(log,
                      "salt.bulk_modulus = %s Pa is too stiff for the grid: its explicit limit "
                      "%.3g s is below the time step %.3g s: lower salt.bulk_modulus or raise "
                      "salt.grid_spacing",
                      v1, dt_pressure, m.dt);
    }
}
