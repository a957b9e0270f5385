/* model: derived constants and the increment schedule (see model.h).
 *
 * Every number that the solver, the summary and the analysis must agree on is computed
 * here once. The boundary speed v = 25 m/s^2 x dt is not stated by the original documents;
 * it is the relation that reproduces all their worked examples (56 / 282 increments and
 * ~1130 m for the default model; axial strain 0.2 in the biaxial test), see
 * docs/parameters.md. Step counts are rounded to the nearest step; the display interval in
 * steps is kept unrounded so increments do not drift over long runs. */
#include "model.h"

#include "file_bounds.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* model units; the largest is the one the parameter checks hold to the file's radius bound */
static const double base_radius[CDEM_NUM_RADII] = {0.05, 0.075, 0.1, CDEM_LARGEST_RADIUS_UNITS};

/* Spring stiffness (N/m) used at unit scaling 1000 m or with keep_constants. */
static const double kn_default = 1544871985.0;
/* damping = dt * this (N s/m per s) with the default constants. */
static const double damping_per_dt = 3.0e9;
/* Scaled constants for unit scaling < 1000 m: Kn = Ks = r_avg * k_per_radius,
 * damping = r_avg * damping_per_radius (r_avg in m). */
static const double kn_per_radius = 19944125.80;
static const double damping_per_radius = 1091596.58430158;

void cdem_model_gravity_vector(double g, double tilt_deg, double *gx, double *gy) {
    if (tilt_deg == 0.0) { /* exactly straight down: no rounding of sin and cos */
        *gx = 0.0;
        *gy = -g;
        return;
    }
    const double t = tilt_deg * M_PI / 180.0;
    *gx = g * sin(t);
    *gy = -(g * cos(t));
}

/* A process's own elements of the given density (kg/m^3): the mass of their smallest class
 * lowers the model's smallest mass, and the lightest of the processes' is remembered (the
 * summary names it). */
static cdem_status process_elements(cdem_model *m, const char *word, const char *key,
                                    double density, cdem_error *err) {
    if (!(density > 0.0) || !isfinite(density))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "cannot derive the model: %s = %g kg/m^3 must be positive", key, density);
    const double mass = density * M_PI * m->radius[0] * m->radius[0];
    if (!m->lightest_process || mass < m->lightest_process_mass) {
        m->lightest_process = word;
        m->lightest_process_mass = mass;
    }
    if (mass < m->min_mass)
        m->min_mass = mass;
    return CDEM_OK;
}

/* Sea-level rise factors, in cdem_sea_level_rise order. */
static const double sea_factor[] = {0.0, 0.25, 0.5, 0.75, 1.0};

cdem_status cdem_model_derive(const cdem_params *p, const cdem_model_mode *mode, cdem_model *m,
                              cdem_error *err) {
    if (!p || !m)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_model_derive: NULL argument");
    memset(m, 0, sizeof *m);
    m->mode = mode ? *mode : cdem_model_mode_default();
    m->moving_flag = CDEM_FLAG_MOVING;
    if (!(fabs(m->mode.gravity_tilt) < 90.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "cannot derive the model: the mode tilts gravity by %g degrees: must be "
                         "within (-90, 90)",
                         m->mode.gravity_tilt);
    if (!(p->unit_scaling > 0) || !(p->width > 0) || !(p->height > 0) || !(p->density > 0) ||
        !(p->runtime > 0) || !(p->equilibration >= 0) || !(p->display_interval > 0) ||
        !isfinite(p->runtime) || !isfinite(p->unit_scaling) || !isfinite(p->density))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "cannot derive the model: unit_scaling = %g m, width = %g, height = %g, "
                         "density = %g kg/m^3, runtime = %g s, equilibration = %g s and "
                         "display_interval = %g must all be positive and finite",
                         p->unit_scaling, p->width, p->height, p->density, p->runtime,
                         p->equilibration, p->display_interval);
    if ((unsigned)p->sea_level_rise >= sizeof sea_factor / sizeof sea_factor[0])
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "cannot derive the model: sea_level_rise = %d",
                         (int)p->sea_level_rise);

    double scale = p->unit_scaling * cdem_params_radius_scale(p);
    double sum = 0.0;
    for (int i = 0; i < CDEM_NUM_RADII; i++) {
        m->radius[i] = base_radius[i] * scale;
        m->mass[i] = p->density * M_PI * m->radius[i] * m->radius[i];
        sum += m->radius[i];
    }
    m->average_radius = sum / CDEM_NUM_RADII;
    m->max_radius = m->radius[CDEM_NUM_RADII - 1];
    m->min_mass = m->mass[0];
    if (p->weak_interval != CDEM_WEAK_OFF && p->weak_density_percent < 100.0) {
        double light = m->mass[0] * p->weak_density_percent / 100.0;
        if (light > 0 && light < m->min_mass)
            m->min_mass = light;
    }
    /* the processes' own elements (common/processes/<id>.h, CDEM_PROCESS_ELEMENTS): a
     * lighter one sets the time step, as a light interval does */
#define CDEM_PROCESS_ELEMENTS(word, key, on, density)                                              \
    if (on)                                                                                        \
        CDEM_TRY(process_elements(m, word, key, density, err));
#include "processes.def"
#undef CDEM_PROCESS_ELEMENTS

    if (p->keep_constants || p->unit_scaling >= 1000.0) {
        m->kn = kn_default;
        m->dt = 0.25 * sqrt(m->min_mass / m->kn);
        m->damping = m->dt * damping_per_dt;
    } else {
        m->kn = m->average_radius * kn_per_radius;
        m->dt = 0.25 * sqrt(m->min_mass / m->kn);
        m->damping = m->average_radius * damping_per_radius;
    }
    m->ks = m->kn;
    if (p->damping_mode == CDEM_DAMPING_CONTACT) /* dashpots on the contacts: deformation
                                                    steps have no absolute damping (run.c) */
        m->contact_damping = p->contact_damping;
    m->boundary_speed = CDEM_BOUNDARY_ACCEL * m->dt;
    m->displacement_per_step = m->boundary_speed * m->dt;
    m->gravity = m->mode.gravity_off ? 0.0 : p->gravity;
    m->width_m = p->width * p->unit_scaling;
    m->height_m = p->height * p->unit_scaling;

    double equil = p->equilibration / m->dt, total = p->runtime / m->dt;
    if (total > 1e15)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "cannot derive the model: runtime = %g s is %.3g time steps of %g s; "
                         "too many",
                         p->runtime, total, m->dt);
    m->equil_steps = lround(equil);
    m->total_steps = lround(total);
    if (m->total_steps < m->equil_steps)
        m->total_steps = m->equil_steps;

    /* the display interval is in m of boundary displacement, in s when no boundary moves */
    if (m->mode.moving_boundaries == 0)
        m->display_steps = p->display_interval / m->dt;
    else
        m->display_steps = p->display_interval / m->displacement_per_step;
    if (m->display_steps < 1.0)
        m->display_steps = 1.0; /* never more than one increment per step */

    long n_equil = lround((double)m->equil_steps / m->display_steps);
    if (n_equil < 1)
        n_equil = 1;
    /* The small tolerance keeps an exact multiple from producing an extra increment. */
    double after = (double)(m->total_steps - m->equil_steps) / m->display_steps;
    long n_after = (long)ceil(after - 1e-9);
    if (n_after < 0)
        n_after = 0;
    if ((double)n_equil + (double)n_after > 2e9)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "cannot derive the model: %ld display increments; increase "
                         "display_interval = %g",
                         n_equil + n_after, p->display_interval);
    m->n_increments_equil = (int)n_equil;
    m->n_increments_total = (int)(n_equil + n_after);

    /* the boundaries' displacement: each moving boundary's counts (two walls moving inward,
     * twice the shortening) */
    m->total_displacement = (double)m->mode.moving_boundaries *
                            (double)(m->total_steps - m->equil_steps) * m->displacement_per_step;
    m->sediment_interval = 30.0 * p->display_interval;
    m->sediment_steps = lround(m->sediment_interval / m->displacement_per_step);
    m->settling_steps = lround(0.2 * p->equilibration / m->dt);
    m->sea_level_factor = sea_factor[p->sea_level_rise];
    m->elements_estimated = cdem_model_estimate_elements(p);
    return CDEM_OK;
}

long cdem_model_increment_step(const cdem_model *m, int k) {
    if (!m || k <= 0)
        return 0;
    if (k >= m->n_increments_total)
        return m->total_steps;
    if (k <= m->n_increments_equil)
        return lround((double)k * (double)m->equil_steps / (double)m->n_increments_equil);
    long step = m->equil_steps + lround((double)(k - m->n_increments_equil) * m->display_steps);
    return step < m->total_steps ? step : m->total_steps;
}

long cdem_model_inversion_step(const cdem_params *p, const cdem_model *m) {
    const long def_steps = m->total_steps - m->equil_steps;
    return p->inversion ? lround(p->inversion_percent / 100.0 * (double)def_steps) : def_steps + 1;
}

long cdem_model_sediment_events(const cdem_params *p, const cdem_model *m) {
    if (!p->sedimentation || m->sediment_steps < 1)
        return 0;
    long last_start = m->total_steps - m->settling_steps - m->equil_steps;
    return last_start >= m->sediment_steps ? last_start / m->sediment_steps : 0;
}

long cdem_model_estimate_elements(const cdem_params *p) {
    if (!p || !(p->width > 0) || !(p->height > 0))
        return 0;
    /* 2121 elements fill the default 10 x 5 unit box at full radii (the paper's count);
     * elements per area grow as the inverse square of the radii (half radii: four times). */
    const double scale = cdem_params_radius_scale(p);
    if (!(scale > 0))
        return 0;
    const double n = 2121.0 / 50.0 / (scale * scale) * p->width * p->height;
    return n < 9e18 ? lround(n) : LONG_MAX;
}
