/* summary: the model summary text (the original program's Summary view).
 *
 * Written into a memory stream (open_memstream), so the caller gets one malloc'd string
 * that cdem-run prints and the file writer stores. Every number carries its unit; nothing
 * depends on the clock or the machine, so the text of a model is reproducible and can be
 * diffed (examples keep their expected summary next to them). Lines are "  label: value"
 * with the label padded to a fixed column (summary_line.h), under unindented headings; the
 * boundary mode writes its own section's lines and says what it changes elsewhere (gravity,
 * a still boundary and the display interval in seconds: its derive hook, in m->mode). */
#include "summary.h"

#include "bc.h"
#include "estimate.h"
#include "h5format.h"
#include "process.h"
#include "run.h"
#include "summary_line.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One line of the summary (summary_line.h). */
#define line cdem_summary_line

static void heading(FILE *f, const char *title) {
    fprintf(f, "\n%s\n", title);
}

static const char *on_off(int v) {
    return v ? "on" : "off";
}

static const char *sea_word(cdem_sea_level_rise s) {
    static const char *const words[] = {"null", "low", "mid", "high", "very high"};
    return (unsigned)s < 5 ? words[s] : "?";
}

/* A duration for a person: s, min or h, three significant digits. */
static void duration(char *buf, size_t size, double s) {
    if (s < 120.0)
        snprintf(buf, size, "%.2g s", s);
    else if (s < 7200.0)
        snprintf(buf, size, "%.3g min", s / 60.0);
    else
        snprintf(buf, size, "%.3g h", s / 3600.0);
}

/* A size in bytes for a person: kB, MB, GB or TB (10^3 steps), three significant digits. */
static void bytes(char *buf, size_t size, double b) {
    static const char *const units[] = {"kB", "MB", "GB", "TB"};
    int u = 0;
    b /= 1e3;
    while (b >= 1e3 && u < 3) {
        b /= 1e3;
        u++;
    }
    snprintf(buf, size, "%.3g %s", b, units[u]);
}

/* What the run will cost and whether its equilibration is long enough (estimate.h): constants
 * of one CPU class and of the file format, never a measurement, so the text stays the same. */
static void estimates_section(FILE *f, const cdem_params *p, const cdem_model *m, long n) {
    heading(f, "Estimates before the run");
    const double steps = (double)m->total_steps, incs = (double)m->n_increments_total + 1.0;
    const double wall = cdem_estimate_wall_seconds((double)n, steps, incs);
    char one[32], two[32], file[32], space[32], mem[32];
    duration(one, sizeof one, wall);
    duration(two, sizeof two, CDEM_ESTIMATE_TWO_THREADS * wall);
    line(f, "element-steps", "%.3g (%ld elements x %ld time steps)", (double)n * steps, n,
         m->total_steps);
    line(f, "wall time",
         "about %s on one thread and %s on two of %s at %g ns per element-step "
         "(docs/performance.md, \"Estimates before a run\"); a busy machine or another CPU "
         "differs",
         one, two, CDEM_ESTIMATE_CPU, CDEM_ESTIMATE_NS_PER_ELEMENT_STEP);
    bytes(file, sizeof file, cdem_h5_estimate_file_size((double)n, incs, p->calculate_stress));
    bytes(space, sizeof space,
          cdem_h5_estimate_run_space((double)n, incs, p->calculate_stress,
                                     p->checkpoint_interval > 0));
    line(f, "output file", "about %s (%.0f increments of %ld elements%s); %s with %s sidecar", file,
         incs, n, p->calculate_stress ? ", with stress" : "", space,
         p->checkpoint_interval > 0 ? "the checkpoint slots and the" : "the");
    bytes(mem, sizeof mem, CDEM_RUN_MEMORY_FIXED + (double)n * CDEM_RUN_MEMORY_PER_ELEMENT);
    line(f, "memory", "about %s (%.0f bytes per element)", mem, CDEM_RUN_MEMORY_PER_ELEMENT);
    if (m->mode.moving_boundaries > 0)
        line(f, "slip over the runtime",
             "%.6g m in the %g s after equilibration (the boundary speed is %g m/s^2 x dt: "
             "smaller elements have a shorter time step and move less in the same runtime)",
             m->total_displacement, p->runtime - p->equilibration, CDEM_BOUNDARY_ACCEL);
    const double need = cdem_estimate_equilibration_needed(m);
    if (need <= 0.0)
        return;
    line(f, "equilibration needed",
         "about %.0f s for an assembly %.0f average diameters tall (rule of thumb, "
         "docs/performance.md, \"Estimates before a run\")",
         need, cdem_estimate_height_diameters(m));
    if (p->equilibration < need)
        line(f, "warning",
             "time.equilibration = %g s is shorter: the assembly will still be settling when "
             "the boundaries start to move; use time.equilibration = %.0f or more (docs/guide.md, "
             "section 4, \"Equilibration\")",
             p->equilibration, need);
}

static void contact_line(FILE *f, const char *label, const cdem_params *p,
                         const cdem_contact_material *c) {
    if (p->material == CDEM_MATERIAL_GRANULAR)
        line(f, label, "friction %g, cohesion %g N", c->friction, c->cohesion);
    else
        line(f, label, "breaking strain %g (bond breaks when r - R >= %g R)", c->breaking_strain,
             c->breaking_strain);
}

/* The summary's section "Elements". */
static void elements_section(FILE *f, long n_elements, long n_wall_elements,
                             int elements_estimated) {
    /* One count everywhere (docs/format.md, "Counting"): the elements stored in increment 0,
     * after the boundary mode has added its fault elements; the progress line and
     * cdem-strain info count the same. */
    heading(f, "Elements");
    line(f, "elements", "%ld in increment 0%s", n_elements + n_wall_elements,
         elements_estimated ? " (estimated from the packing density; the exact count is known "
                              "once the assembly is generated)"
                            : " (escaping, eroded and deposited elements change it later)");
    line(f, "free elements", "%ld%s", n_elements, elements_estimated ? " (estimated)" : "");
    line(f, "wall and fault elements", "%ld%s", n_wall_elements,
         elements_estimated ? " (estimated)" : "");
}

/* The summary's section "Model dimensions". */
static void dimensions_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Model dimensions");
    line(f, "assembly", "%g x %g units = %.6g x %.6g m", p->width, p->height, m->width_m,
         m->height_m);
    line(f, "unit scaling", "%g m per unit", p->unit_scaling);
    line(f, "lateral wall height", "%.6g m (%d x the assembly height)",
         p->wall_height_multiplier * m->height_m, p->wall_height_multiplier);
    line(f, "random seed", "%ld", p->seed);
}

/* The summary's section "Element radii and masses". */
static void radii_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Element radii and masses");
    const double scale = cdem_params_radius_scale(p);
    if (scale == 1.0)
        line(f, "radii", "full (0.05-0.125 units)");
    else if (scale == 0.5)
        line(f, "radii", "half (0.025-0.0625 units)");
    else
        line(f, "radii", "%.6g-%.6g units (%g x the full radii)", 0.05 * scale, 0.125 * scale,
             scale);
    for (int i = 0; i < CDEM_NUM_RADII; i++) {
        char label[32];
        snprintf(label, sizeof label, "radius %d", i + 1);
        line(f, label, "%.6g m, mass %.6g kg/m", m->radius[i], m->mass[i]);
    }
    line(f, "average radius", "%.6g m", m->average_radius);
    char lightest[64] = ""; /* whose elements set the smallest mass, when not the cover's */
    if (m->lightest_process && m->min_mass == m->lightest_process_mass)
        snprintf(lightest, sizeof lightest, " (%s)", m->lightest_process);
    else if (m->min_mass < m->mass[0])
        snprintf(lightest, sizeof lightest, " (light interval)");
    line(f, "smallest mass", "%.6g kg/m%s", m->min_mass, lightest);
}

/* The summary's section "Constants". */
static void constants_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Constants");
    const char *kn_origin = p->unit_scaling >= 1000.0 ? "default constant"
                            : p->keep_constants       ? "default constant (keep_constants = on)"
                                                      : "scaled with the average radius";
    line(f, "normal stiffness Kn", "%.10g N/m (%s)", m->kn, kn_origin);
    line(f, "shear stiffness Ks", "%.10g N/m", m->ks);
    if (p->damping_mode == CDEM_DAMPING_CONTACT)
        line(f, "damping",
             "%.8g N s/m in equilibration and settling; contact dashpots of %g "
             "of critical on deformation steps (physics.damping_mode = contact)",
             m->damping, p->contact_damping);
    else if (p->deformation_damping == 1.0)
        line(f, "damping", "%.8g N s/m", m->damping);
    else
        line(f, "damping", "%.8g N s/m; x %g on deformation steps (physics.deformation_damping)",
             m->damping, p->deformation_damping);
    line(f, "time step dt", "%.6g s (0.25 sqrt(smallest mass / Kn))", m->dt);
    if (m->mode.gravity_tilt != 0.0 && m->gravity > 0.0) {
        double gx, gy;
        cdem_model_gravity_vector(m->gravity, m->mode.gravity_tilt, &gx, &gy);
        line(f, "gravity", "%g m/s^2, tilted %g degrees from -y toward %s: (%.6g, %.6g) m/s^2",
             m->gravity, fabs(m->mode.gravity_tilt), m->mode.gravity_tilt > 0.0 ? "+x" : "-x", gx,
             gy);
    } else
        line(f, "gravity", "%g m/s^2%s%s%s", m->gravity, m->mode.gravity_off ? " (" : "",
             m->mode.gravity_off ? m->mode.gravity_off : "", m->mode.gravity_off ? ")" : "");
    line(f, "density", "%g kg/m^3", p->density);
    line(f, "stress calculation", "%s", on_off(p->calculate_stress));
}

/* The summary's section "Time". */
static void time_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Time");
    line(f, "equilibration", "%g s = %ld time steps", p->equilibration, m->equil_steps);
    line(f, "runtime", "%g s = %ld time steps (%ld after equilibration)", p->runtime,
         m->total_steps, m->total_steps - m->equil_steps);
    line(f, "time-series sample", "every %d time steps", p->series_interval);
}

/* The summary's section "Boundary displacement". */
static void boundary_displacement_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Boundary displacement");
    if (m->mode.moving_boundaries == 0) {
        line(f, "boundary speed", "none (%s)", m->mode.still ? m->mode.still : "no boundary moves");
    } else {
        line(f, "boundary speed", "%.6g m/s (%g m/s^2 x dt)", m->boundary_speed,
             CDEM_BOUNDARY_ACCEL);
        line(f, "displacement per step", "%.6g m", m->displacement_per_step);
        line(f, "total displacement", "%.6g m (first-order estimate%s)", m->total_displacement,
             p->sedimentation ? "; settling pauses make it smaller" : "");
    }
}

/* The summary's section "Display increments". */
static void increments_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Display increments");
    if (m->mode.moving_boundaries == 0) /* no boundary moves: the interval is in seconds */
        line(f, "display interval", "%g s = %.6g time steps", p->display_interval,
             m->display_steps);
    else
        line(f, "display interval", "%g m = %.6g time steps", p->display_interval,
             m->display_steps);
    /* increments are numbered 0..N and the file holds N + 1 of them (0 = before equilibration) */
    line(f, "increments", "%d, numbered 0..%d", m->n_increments_total + 1, m->n_increments_total);
    line(f, "end of equilibration", "increment %d", m->n_increments_equil);
}

/* The summary's section "Faulting / boundary conditions". */
static void boundary_conditions_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Faulting / boundary conditions");
    line(f, "mode", "%s", cdem_mode_name(p->mode));
    cdem_bc_describe(p, m, f);
}

/* The summary's section "Material". */
static void material_section(FILE *f, const cdem_params *p) {
    heading(f, "Material");
    line(f, "model", "%s",
         p->material == CDEM_MATERIAL_GRANULAR ? "granular frictional-cohesive"
                                               : "initially bonded");
    if (p->material == CDEM_MATERIAL_GRANULAR) {
        line(f, "contact law", "%s: %s", cdem_law_name(p->granular_law),
             cdem_law_description(p->granular_law));
        line(f, "cohesive contacts", "%s",
             p->cohesive_contacts == CDEM_COHESIVE_FORMED
                 ? "those of the end of equilibration and every contact formed later"
             : p->cohesive_contacts == CDEM_COHESIVE_INITIAL
                 ? "the contacts of the built assembly that never separated, at the end of "
                   "equilibration"
                 : "those of the end of equilibration");
        line(f, "cohesion lost", "%s",
             p->first_slip ? "at the first slip (first slip on)"
                           : "when the pair separates (first slip off)");
        if (p->settling_friction != 1.0)
            line(f, "settling friction", "friction x %g during equilibration",
                 p->settling_friction);
    }
    contact_line(f, "element-element", p, &p->element);
    contact_line(f, "element-wall", p, &p->wall);
    cdem_contact_material base;
    if (cdem_params_base_material(p, &base))
        contact_line(f, "element-base", p, &base);
    else
        line(f, "element-base", "as element-wall");
    contact_line(f, "element-fault", p, &p->fault);
}

/* The summary's section "Heterogeneity". */
static void heterogeneity_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Heterogeneity");
    line(f, "flexural slip", "%s",
         !p->flexural_slip ? "off"
         : p->flexural_slip_style == CDEM_FLEX_WEAK_LAYERS
             ? "on, weak layers (no strength on contacts of layers 4, 8, 12, 16 and 20, from "
               "the end of equilibration)"
             : "on (no strength between pre-growth layers, from the end of equilibration)");
    if (p->weak_interval == CDEM_WEAK_OFF) {
        line(f, "weak/light interval", "off");
    } else {
        line(f, "weak/light interval",
             "%s %g %% of the height = %.6g m (of the initial span of element centres; "
             "fixed at assembly, flagged weak)",
             p->weak_interval == CDEM_WEAK_LOWER ? "lower" : "upper", p->weak_thickness_percent,
             p->weak_thickness_percent / 100.0 * m->height_m);
        line(f, "mixed pairs", "a pair with one weak element uses the weak values");
        line(f, "interval strength", "%g %% of the material values", p->weak_strength_percent);
        line(f, "interval density", "%g %% = %g kg/m^3", p->weak_density_percent,
             p->weak_density_percent / 100.0 * p->density);
    }
    if (p->layered_friction)
        line(f, "layered friction",
             "layers 5-8, 13-16, 21-24 friction %g (a pair with either element in such a "
             "layer)",
             p->layered_friction_value);
    else
        line(f, "layered friction", "off");
    line(f, "pre-growth layers", "%d of equal thickness", CDEM_PREGROWTH_LAYERS);
}

/* The summary's section "Surface processes". */
static void surface_section(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Surface processes");
    if (p->overburden_pressure > 0)
        line(f, "overburden pressure",
             "%g N/m on the top surface: %g N on the highest element of each %g m column "
             "(2 x the largest radius), found again at every neighbour-list rebuild",
             p->overburden_pressure, p->overburden_pressure * 2.0 * m->max_radius,
             2.0 * m->max_radius);
    else
        line(f, "overburden pressure", "off");
    if (p->erosion)
        line(f, "erosion",
             "above %g x the assembly height = %.6g m (exactly: the level x the span of "
             "element centres at the end of equilibration, above the lowest centre); "
             "elements above it removed before each deformation increment",
             p->erosion_base_level, p->erosion_base_level * m->height_m);
    else
        line(f, "erosion", "off");
    if (p->sedimentation) {
        line(f, "sedimentation", "on (growth strata)");
        line(f, "sediment interval", "%g m of boundary displacement = %ld time steps",
             m->sediment_interval, m->sediment_steps);
        line(f, "settling time", "%g s = %ld time steps (boundaries still)", 0.2 * p->equilibration,
             m->settling_steps);
        if (m->boundary_speed > 0)
            line(f, "time between sediments", "%.6g s", m->sediment_interval / m->boundary_speed);
        line(f, "sea-level rise", "%s (factor %g of the boundary displacement)",
             sea_word(p->sea_level_rise), m->sea_level_factor);
        line(f, "growth sequence 1", "%d layers", p->growth_sequence1_layers);
    } else {
        line(f, "sedimentation", "off");
    }
}

cdem_status cdem_summary_text(const cdem_params *p, const cdem_model *m, long n_elements,
                              long n_wall_elements, int elements_estimated, char **text,
                              cdem_error *err) {
    /* n_elements: free elements; n_wall_elements: wall, fault and other boundary elements */
    if (text)
        *text = NULL;
    if (!p || !m || !text)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_summary_text: NULL argument");
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "model summary: cannot open a memory stream");

    fprintf(f, "cdem-c model summary\n");
    elements_section(f, n_elements, n_wall_elements, elements_estimated);
    dimensions_section(f, p, m);
    radii_section(f, p, m);
    constants_section(f, p, m);
    time_section(f, p, m);
    boundary_displacement_section(f, p, m);
    increments_section(f, p, m);
    boundary_conditions_section(f, p, m);
    material_section(f, p);
    heterogeneity_section(f, p, m);
    cdem_processes_describe(p, m, f); /* each process's section (process.h) */
    surface_section(f, p, m);

    estimates_section(f, p, m, n_elements + n_wall_elements);

    if (fclose(f) != 0 || !buf) {
        free(buf);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "model summary: out of memory");
    }
    *text = buf;
    return CDEM_OK;
}
