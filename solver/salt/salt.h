/* salt: a Newtonian salt made of elements whose stress lives on a background grid (a
 * material-point continuum, MPM), under the frictional-cohesive cover of the pair list. Why
 * not a contact law: a frictionless packing held apart by its contacts keeps a friction of
 * about 0.12 x the pressure, a thousand times a basin salt's viscous stress; on the grid a
 * uniform pressure gives no force, so there is no frictional yield. Each salt element carries
 * its area ratio J (p = K (1/J - 1), no tension); a force evaluation does P2G (the salt, then
 * the non-salt elements that share its nodes: the no-slip contacts), the gradient and
 * sigma = -p I + 2 eta D', the node forces and G2P, and the salt's pairs with the law of
 * salt_law.h; after a step the salt is projected back onto a grid of its own
 * (cdem_salt_project), which moves it and whose divergence J follows. The formulas and
 * measurements: docs/solver.md, section 9.
 * Determinism: serial sums in element or pair order, the same bits for any thread count.
 * Lifetime: the grid, the scratch and the pair list are sized at list builds, never in a step.
 * Ownership: cdem_salt owns its scratch, never the state. Units: SI (m, s, kg per metre, N per
 * metre, Pa). */
#ifndef CDEM_SALT_H
#define CDEM_SALT_H

#include "cdem_error.h"
#include "model.h"
#include "neighbour.h"
#include "params.h"
#include "state.h"
#include "viscous.h"

#include <stddef.h>
#include <stdint.h>

/* salt.rate is in mm per year (CDEM_SECONDS_PER_YEAR, model.h). */

/* The salt's constants (salt.*; docs/solver.md, "Salt"), all 0 when salt.layer = off. The
 * model runs at natural lengths, densities and gravity but with time compressed by
 * time_scale S = boundary speed / geological rate; the salt's model viscosity is the
 * geological one / S, which keeps the ratio of viscous to gravitational and frictional
 * stresses (eta V / (rho g h H)) of nature. The salt elements' density is also declared to
 * the model (common/processes/salt.h, CDEM_PROCESS_ELEMENTS), whose smallest mass, and so
 * whose time step, a lighter salt sets. */
typedef struct {
    int on;                      /* 1: salt.layer is basal or interval */
    double density;              /* kg/m^3 */
    double mass[CDEM_NUM_RADII]; /* kg per metre, density * pi r^2 of each radius class */
    double viscosity_geological; /* Pa s, salt.viscosity */
    double rate;                 /* m/s, salt.rate in SI */
    double time_scale;           /* S: geological seconds per model second */
    double viscosity;            /* Pa s, the model's: viscosity_geological / S */
    double bulk_modulus;         /* Pa */
    double grid_spacing;         /* m, salt.grid_spacing x the average radius */
    double reach;                /* the pair dashpots' reach / (r_i + r_j) */
    double dashpot_fraction;     /* alpha of the pair dashpots */
} cdem_salt_model;

/* The salt's constants of p on the model m (cdem_model_derive's, whose boundary speed gives
 * the time scale): *sm all 0 when salt.layer is off; CDEM_ERR_RANGE for a model viscosity
 * that is not positive and finite. */
cdem_status cdem_salt_model_derive(const cdem_params *p, const cdem_model *m, cdem_salt_model *sm,
                                   cdem_error *err);

/* What the placement measured (cdem_salt_place, cdem_salt_measure): the constants of the
 * salt's discretisation. A resumed run places the salt of the same assembly again and gets
 * the same values. */
typedef struct {
    long elements;           /* salt elements placed */
    double band_lo, band_hi; /* m: the salt's band of element centres (placement) */
    double disc_area;        /* m^2: sum of pi r^2 over the salt elements */
    double phi;              /* their packing fraction in their region: the material area of an
                                element is J pi r^2 / phi */
    double beta;             /* affine constant of a central dashpot network in simple shear: the
                                material area over sum over salt pairs of w d^2 / 8 */
    int max_pairs;           /* most salt dashpot pairs on one salt element */
} cdem_salt_layer;

/* Which elements that are not salt join the grid (salt.*_contact = no-slip). */
enum {
    CDEM_SALT_JOIN_COVER = 1u << 0, /* free elements */
    CDEM_SALT_JOIN_BASE = 1u << 1,  /* the base row and fault / mylar elements */
    CDEM_SALT_JOIN_WALLS = 1u << 2, /* the other wall elements (lateral walls, plates) */
};

typedef struct {
    /* configuration (cdem_salt_configure) */
    int on;                 /* 0: no salt, the module does nothing */
    double viscosity;       /* Pa s, the model's */
    double bulk_modulus;    /* Pa */
    double h;               /* m, node spacing */
    double reach;           /* dashpot reach / (r_i + r_j), >= 1 */
    double dashpot;         /* N s/m, the pair dashpots' coefficient c */
    double phi;             /* packing fraction of the placed salt */
    double kn;              /* N/m, repulsion between salt and other elements */
    double contact_damping; /* fraction of critical of a touching salt-other pair's dashpot */
    unsigned join;          /* CDEM_SALT_JOIN_* */
    double skin;            /* m, the pair list's skin (the salt pairs' list uses it too) */

    /* grid: node (a, b) at ((gx0 + a) h, (gy0 + b) h), a < gnx, b < gny (set at builds) */
    long gx0, gy0;
    size_t gnx, gny, gcap;
    double *gm, *gmx, *gmy, *gfx, *gfy; /* node mass, momentum, force */
    double *gbm, *gbx, *gby;            /* the non-salt elements' node mass and momentum
                                           (cover, base, faults, walls, plates) */
    unsigned char *gsalt;               /* flags: 1 a salt element weighs on the node, 4 it
                                           is within half a cell of a non-salt element's
                                           surface */

    /* per element (ecap), valid for the state of the last build */
    size_t ecap;
    double *lxx, *lxy, *lyx, *lyy; /* 1/s: the velocity gradient L_ab = d v_a / d x_b of the
                                      last evaluation (the area update, the projection) */
    double *sxx, *syy, *sxy;       /* Pa: the continuum stress of the last evaluation (salt),
                                      compression positive */
    int32_t *members;              /* elements in P2G, salt first, then the others */
    size_t n_members;

    /* the salt's pairs (built at each list build): i < j, at least one of them salt */
    int32_t *pi, *pj;
    size_t np, pcap;
} cdem_salt;

/* The salt's time mapping and its dimensionless numbers (docs/solver.md, section 9.4),
 * from the parameters and the model alone (before any element exists: the packing fraction
 * is taken as CDEM_SALT_RULES_PHI, below every measured placement). Model and nature share
 * lengths, densities and gravity; time is compressed by S = V_model / V_geological, and the
 * model's viscosity is eta / S, which keeps eta V / (rho g h H) of nature. */
typedef struct {
    double salt_thickness;  /* m: the band's share of the assembly height */
    double cover_thickness; /* m: the assembly height above the band */
    double time_scale;      /* S: geological seconds per model second */
    double viscosity_model; /* Pa s, eta / S */
    double boundary_speed;  /* m/s in the model (25 m/s^2 x dt) */
    double rate;            /* m/s in nature (salt.rate) */
    double pi_ratio;        /* eta V / (rho g h_s H_c): viscous against gravitational and
                               frictional stress (NaN without gravity) */
    double reynolds;        /* rho_s V_model h_s / eta_model: must stay << 1 */
    double damping_number;  /* D: the absolute damping's drag on a cover moving over the salt
                               against the salt's viscous traction */
    double dt_viscous;      /* s, the grid's explicit viscous limit rho phi h^2 / (8 eta) */
    double dt_pressure;     /* s, the grid's explicit pressure limit 0.25 sqrt(m / k) */
    double deformation_yr;  /* years of geology in the deformation phase (runtime minus
                               equilibration, times S) */
} cdem_salt_time;

/* The packing fraction the checks and the summary assume for the salt. */
#define CDEM_SALT_RULES_PHI 0.75

/* Fills *t (all 0 when salt.layer is off), sm: cdem_salt_model_derive's. */
void cdem_salt_time_map(const cdem_params *p, const cdem_model *m, const cdem_salt_model *sm,
                        cdem_salt_time *t);

/* The salt's parameter rules (cdem-run's validation): bonded cover, weak interval and modes
 * that exclude it, the interval's order, absolute damping, the time-step limits. */
void cdem_salt_rules(const cdem_params *p, cdem_rule_log *log);

/* Places the salt of salt.layer in the built assembly (before equilibration, like the weak
 * interval): the free elements whose centre lies in the band get CDEM_FLAG_SALT, the salt's
 * mass (sm) and J = 1; *layer receives what cdem_salt_measure measures. Does nothing when
 * salt.layer is off (layer zeroed). */
cdem_status cdem_salt_place(const cdem_params *p, const cdem_model *m, const cdem_salt_model *sm,
                            cdem_state *s, cdem_salt_layer *layer, cdem_error *err);

/* Measures the salt elements of s, which fill a region of area region_area (m^2): their disc
 * area, packing fraction, beta (with the pair dashpots' reach) and the most pairs of one. */
cdem_status cdem_salt_measure(const cdem_state *s, double region_area, double reach,
                              cdem_salt_layer *layer, cdem_error *err);

/* Sets the module up from the salt's constants sm and the placement (sm->on = 0: off), with
 * the model's repulsion kn, its time step dt (caps the pair dashpots so that they never set
 * it), its contact damping (0 with absolute damping); skin: the pair list's. */
cdem_status cdem_salt_configure(cdem_salt *salt, const cdem_model *m, const cdem_salt_model *sm,
                                const cdem_params *p, const cdem_salt_layer *layer, double skin,
                                cdem_error *err);

/* The configured module's forces join the step of the viscous module v (viscous.h): its grid
 * and pairs after each list build, its forces each step, its area update after each step.
 * The salt must outlive v's use of it. Nothing when salt->on is 0. */
cdem_status cdem_salt_join(cdem_salt *salt, cdem_viscous *v, cdem_error *err);

/* The model's coefficient of the pair dashpots: dashpot_fraction x beta x viscosity, capped
 * at 0.25 m_min / (max_pairs dt). */
double cdem_salt_dashpot(const cdem_salt_model *sm, const cdem_salt_layer *layer, double min_mass,
                         double dt);

void cdem_salt_free(cdem_salt *salt);

/* After each list build (the state's order may have changed) and after a checkpoint's list
 * is restored: the grid sized to the salt, the scratch to the elements, the salt's pairs
 * listed, all from the positions of the list's build (nb->x0, y0), so that a resumed run has
 * the grid and the pairs of the run it continues. */
cdem_status cdem_salt_after_build(cdem_salt *salt, const cdem_neighbour *nb, const cdem_state *s,
                                  cdem_error *err);

/* The salt's forces of the current positions and velocities added into ex, ey (one per
 * element); L and the stress of each salt element kept for cdem_salt_project and
 * cdem_salt_stress. */
void cdem_salt_forces(cdem_salt *salt, const cdem_state *s, double *ex, double *ey);

/* After a time step of length dt, the salt made a continuum of material points again (MPM's
 * transfer back from the grid), from a grid of the salt alone:
 *  - each salt element's velocity is replaced by the grid's at its centre, the grid's
 *    velocities made from the salt's new velocities with each element's velocity gradient L
 *    (an affine transfer, APIC): a linear field passes unchanged, momentum and angular
 *    momentum are kept, and the element motions the grid cannot see (the null space of the
 *    material points) are removed;
 *  - it is moved by the salt's own velocities on that grid, the plain (not affine) momentum
 *    over the mass of the nodes, rather than with its own mid-step velocity
 *    (x += dt (v_plain - v_half)), as a material point is advected by the grid;
 *  - its area ratio follows the divergence of that same field, J <- J exp(dt div v_plain), so
 *    that salt that converges is compressed and salt that spreads is dilated, and its pressure
 *    resists both (J following tr L of the forces' grid, whose nodes next to the cover and the
 *    base carry their velocities, let the salt's elements crowd unseen; moving them with the
 *    affine field, which carries that L, spread them by 11 % at rest unseen: docs/solver.md 9.5);
 *  - then relaxed by CDEM_SALT_J_RELAX toward the grid's mass-weighted mean of the salt's J
 *    around it, which keeps the salt's area (sum m J) exactly.
 * Without them the elements drift inside the grid's cells and their J random-walk apart: the
 * salt gathers in bands a cell apart under gravity within minutes of model time, and its
 * pressure noise reaches its mean. */
void cdem_salt_project(cdem_salt *salt, cdem_state *s, double dt);

/* The fraction of its difference to the grid's mean J that an element's J loses in a step. */
#define CDEM_SALT_J_RELAX 0.01

/* The salt elements' stress of the last evaluation into the state's stress arrays
 * (compression positive; the cover keeps its Love-Weber stress). */
void cdem_salt_stress(const cdem_salt *salt, cdem_state *s);

/* The salt's pressure K (1/J - 1), no tension. */
static inline double cdem_salt_pressure(double bulk_modulus, double area_ratio) {
    const double p = bulk_modulus * (1.0 / area_ratio - 1.0);
    return p > 0.0 ? p : 0.0;
}

/* What the series reports of the salt (run_output.c): its material area sum J pi r^2 / phi
 * (m^2), the highest top y + r of a salt element (m; NaN without salt) and its count. */
void cdem_salt_measures(const cdem_state *s, double phi, double *area, double *top, long *count);

#endif
