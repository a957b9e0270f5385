/* summary: the model summary text (the original program's Summary view).
 *
 * Written into a memory stream (open_memstream), so the caller gets one malloc'd string
 * that cdem-run prints and the file writer stores. Every number carries its unit; nothing
 * depends on the clock or the machine, so the text of a model is reproducible and can be
 * diffed (examples keep their expected summary next to them). Lines are "  label: value"
 * with the label padded to a fixed column, under unindented headings. */
#include "summary.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LABEL_WIDTH 28

static void heading(FILE *f, const char *title) {
    fprintf(f, "\n%s\n", title);
}

static void line(FILE *f, const char *label, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void line(FILE *f, const char *label, const char *fmt, ...) {
    fprintf(f, "  %s:%*s", label,
            (int)(LABEL_WIDTH - strlen(label)) > 1 ? (int)(LABEL_WIDTH - strlen(label)) : 1, "");
    va_list ap;
    va_start(ap, fmt);
    vfprintf(f, fmt, ap);
    va_end(ap);
    fputc('\n', f);
}

static const char *on_off(int v) {
    return v ? "on" : "off";
}

static const char *sense_word(cdem_fault_sense s) {
    return s == CDEM_SENSE_REVERSE ? "reverse" : "normal";
}

static const char *other_sense_word(cdem_fault_sense s) {
    return s == CDEM_SENSE_REVERSE ? "normal" : "reverse";
}

static const char *walls_word(cdem_walls_choice w) {
    return w == CDEM_WALLS_BOTH ? "both walls" : "right wall";
}

static const char *sea_word(cdem_sea_level_rise s) {
    static const char *const words[] = {"null", "low", "mid", "high", "very high"};
    return (unsigned)s < 5 ? words[s] : "?";
}

static void contact_line(FILE *f, const char *label, const cdem_params *p,
                         const cdem_contact_material *c) {
    if (p->material == CDEM_MATERIAL_GRANULAR)
        line(f, label, "friction %g, cohesion %g N", c->friction, c->cohesion);
    else
        line(f, label, "breaking strain %g (bond breaks when r - R >= %g R)", c->breaking_strain,
             c->breaking_strain);
}

static void fault_common(FILE *f, const cdem_params *p, const cdem_model *m) {
    line(f, "sense", "%s", sense_word(p->fault_sense));
    line(f, "fault location", "%g of the base = %.6g m from the left end", p->fault_location,
         p->fault_location * m->width_m);
}

static void inversion_lines(FILE *f, const cdem_params *p, const cdem_model *m) {
    if (!p->inversion) {
        line(f, "inversion", "off");
        return;
    }
    double before = m->total_displacement * p->inversion_percent / 100.0;
    double after = m->total_displacement - before;
    double net = before - after;
    line(f, "inversion", "at %g %% of the displacement: %.4g m %s, then %.4g m %s",
         p->inversion_percent, before, sense_word(p->fault_sense), after,
         other_sense_word(p->fault_sense));
    if (fabs(net) <= 1e-9 * m->total_displacement)
        line(f, "net displacement", "0 m (the block returns to its starting position)");
    else
        line(f, "net displacement", "%.4g m %s", fabs(net),
             net > 0 ? sense_word(p->fault_sense) : other_sense_word(p->fault_sense));
}

static void write_mode(FILE *f, const cdem_params *p, const cdem_model *m) {
    heading(f, "Faulting / boundary conditions");
    line(f, "mode", "%s", cdem_mode_name(p->mode));
    switch (p->mode) {
    case CDEM_MODE_PLANAR_FAULT:
        fault_common(f, p, m);
        line(f, "fault dip", "%g degrees", p->fault_dip);
        inversion_lines(f, p, m);
        break;
    case CDEM_MODE_LISTRIC_FAULT:
    case CDEM_MODE_IRREGULAR_FAULT:
        fault_common(f, p, m);
        if (p->mode == CDEM_MODE_LISTRIC_FAULT)
            line(f, "fault dip", "%g degrees at the base, steepening to 90 degrees", p->fault_dip);
        else
            line(f, "fault vertices", "%s (x y in m, from the base up-dip)", p->fault_file);
        line(f, "kinematics", "%s",
             p->kinematics == CDEM_KIN_CD ? "constant displacement (CD, mylar sheet)"
                                          : "constant heave (CH)");
        line(f, "footwall", "removed (hanging-wall deformation only)");
        inversion_lines(f, p, m);
        break;
    case CDEM_MODE_VERTICAL_FAULTS:
        line(f, "sense", "%s",
             p->vertical_sense == CDEM_VERT_PISTON ? "piston (block up, compression)"
                                                   : "caldera (block down, extension)");
        line(f, "first fault", "%g of the base = %.6g m from the left end",
             p->vertical_fault_location, p->vertical_fault_location * m->width_m);
        line(f, "second fault", "%g of the base = %.6g m from the left end",
             p->vertical_fault_location + p->vertical_fault_spacing,
             (p->vertical_fault_location + p->vertical_fault_spacing) * m->width_m);
        line(f, "block width", "%.6g m", p->vertical_fault_spacing * m->width_m);
        break;
    case CDEM_MODE_DETACHMENT:
        line(f, "moving walls", "%s, moving inward over the base",
             p->detachment_walls == CDEM_WALLS_BOTH ? "both walls" : "right wall");
        break;
    case CDEM_MODE_REPOSE:
        line(f, "walls removed", "%s, at the end of equilibration", walls_word(p->repose_walls));
        line(f, "base", "extends %.6g m (the assembly's width) beyond %s", m->width_m,
             p->repose_walls == CDEM_WALLS_BOTH ? "each removed wall" : "the removed wall");
        break;
    case CDEM_MODE_BIAXIAL:
        line(f, "confining pressure",
             "%g N/m (%g MPa in 3-D), ramped from zero at %g s to full at %g s",
             p->confining_pressure, p->confining_pressure / 1e6, 0.5 * p->equilibration,
             p->equilibration);
        line(f, "axial strain", "%.4g at the end (platens shorten the %.6g m high sample)",
             m->total_displacement / m->height_m, m->height_m);
        line(f, "gravity", "off");
        break;
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

    heading(f, "Model dimensions");
    line(f, "assembly", "%g x %g units = %.6g x %.6g m", p->width, p->height, m->width_m,
         m->height_m);
    line(f, "unit scaling", "%g m per unit", p->unit_scaling);
    line(f, "lateral wall height", "%.6g m (%d x the assembly height)",
         p->wall_height_multiplier * m->height_m, p->wall_height_multiplier);
    line(f, "random seed", "%ld", p->seed);

    heading(f, "Element radii and masses");
    line(f, "radii", "%s", p->half_radii ? "half (0.025-0.0625 units)" : "full (0.05-0.125 units)");
    for (int i = 0; i < CDEM_NUM_RADII; i++) {
        char label[32];
        snprintf(label, sizeof label, "radius %d", i + 1);
        line(f, label, "%.6g m, mass %.6g kg/m", m->radius[i], m->mass[i]);
    }
    line(f, "average radius", "%.6g m", m->average_radius);
    line(f, "smallest mass", "%.6g kg/m%s", m->min_mass,
         m->min_mass < m->mass[0] ? " (light interval)" : "");

    heading(f, "Constants");
    const char *kn_origin = p->unit_scaling >= 1000.0 ? "default constant"
                            : p->keep_constants       ? "default constant (keep_constants = on)"
                                                      : "scaled with the average radius";
    line(f, "normal stiffness Kn", "%.10g N/m (%s)", m->kn, kn_origin);
    line(f, "shear stiffness Ks", "%.10g N/m", m->ks);
    if (p->deformation_damping == 1.0)
        line(f, "damping", "%.8g N s/m", m->damping);
    else
        line(f, "damping", "%.8g N s/m; x %g on deformation steps (physics.deformation_damping)",
             m->damping, p->deformation_damping);
    line(f, "time step dt", "%.6g s (0.25 sqrt(smallest mass / Kn))", m->dt);
    line(f, "gravity", "%g m/s^2%s", m->gravity,
         p->mode == CDEM_MODE_BIAXIAL ? " (off in the biaxial test)" : "");
    line(f, "density", "%g kg/m^3", p->density);
    line(f, "stress calculation", "%s", on_off(p->calculate_stress));

    heading(f, "Time");
    line(f, "equilibration", "%g s = %ld time steps", p->equilibration, m->equil_steps);
    line(f, "runtime", "%g s = %ld time steps (%ld after equilibration)", p->runtime,
         m->total_steps, m->total_steps - m->equil_steps);
    line(f, "time-series sample", "every %d time steps", p->series_interval);

    heading(f, "Boundary displacement");
    if (p->mode == CDEM_MODE_REPOSE) {
        line(f, "boundary speed", "none (walls removed; the assembly collapses under gravity)");
    } else {
        line(f, "boundary speed", "%.6g m/s (%g m/s^2 x dt)", m->boundary_speed,
             CDEM_BOUNDARY_ACCEL);
        line(f, "displacement per step", "%.6g m", m->displacement_per_step);
        line(f, "total displacement", "%.6g m (first-order estimate%s)", m->total_displacement,
             p->sedimentation ? "; settling pauses make it smaller" : "");
    }

    heading(f, "Display increments");
    if (p->mode == CDEM_MODE_REPOSE)
        line(f, "display interval", "%g s = %.6g time steps", p->display_interval,
             m->display_steps);
    else
        line(f, "display interval", "%g m = %.6g time steps", p->display_interval,
             m->display_steps);
    /* increments are numbered 0..N and the file holds N + 1 of them (0 = before equilibration) */
    line(f, "increments", "%d, numbered 0..%d", m->n_increments_total + 1, m->n_increments_total);
    line(f, "end of equilibration", "increment %d", m->n_increments_equil);

    write_mode(f, p, m);

    heading(f, "Material");
    line(f, "model", "%s",
         p->material == CDEM_MATERIAL_GRANULAR ? "granular frictional-cohesive"
                                               : "initially bonded");
    if (p->material == CDEM_MATERIAL_GRANULAR) {
        static const char *const laws[CDEM_LAW_COUNT] = {
            "normal-cohesion: shear strength mu (Fn + C0)", "coulomb: shear strength mu Fn + C0",
            "spring-cohesion: Fs = Ks Xs + C0, shear strength mu Fn"};
        line(f, "contact law", "%s",
             (int)p->granular_law >= 0 && p->granular_law < CDEM_LAW_COUNT ? laws[p->granular_law]
                                                                           : "?");
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
    cdem_contact_material base = p->base;
    const int own = !(isnan(base.friction) && isnan(base.cohesion) && isnan(base.breaking_strain));
    if (isnan(base.friction))
        base.friction = p->wall.friction;
    if (isnan(base.cohesion))
        base.cohesion = p->wall.cohesion;
    if (isnan(base.breaking_strain))
        base.breaking_strain = p->wall.breaking_strain;
    if (own)
        contact_line(f, "element-base", p, &base);
    else
        line(f, "element-base", "as element-wall");
    contact_line(f, "element-fault", p, &p->fault);

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

    if (fclose(f) != 0 || !buf) {
        free(buf);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "model summary: out of memory");
    }
    *text = buf;
    return CDEM_OK;
}
