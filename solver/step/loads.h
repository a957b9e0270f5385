/* loads: the external loads on the free elements besides the contacts, as the force pass
 * applies them (cdem_force_loads): gravity, the overburden and the confining pressure.
 * Overburden: at each list rebuild the highest free element of each column (width 2 x max
 * radius) is flagged CDEM_FLAG_SURFACE and carries a constant force -p x column width in y
 * until the next rebuild. Confining pressure: the same sideways on the band edges
 * (cdem_loads_find_edges), ramped during equilibration (cdem_bc_confining_ramp).
 * The surface and edge elements are state flags (they move with the elements through the
 * re-sorts and are stored with the state); this module holds the settings, the ramp and the
 * per-column scratch of the searches. Thread safety: one per integrator. Units: SI (m, N/m,
 * N). */
#ifndef CDEM_LOADS_H
#define CDEM_LOADS_H

#include "cdem_error.h"
#include "force.h"
#include "state.h"

typedef struct {
    double gravity;              /* m/s^2, the magnitude (>= 0): checked on resume */
    double gravity_x, gravity_y; /* m/s^2, the acceleration of this step in the model's frame:
                                    (0, -gravity) unless a mode tilts it (set_gravity) */
    double model_gx, model_gy;   /* m/s^2, the model's direction (init's): what a process turns
                                    when the mode sets none (integrate.h, gravity_turn) */
    double column_width; /* m, width of the surface columns and edge bands = 2 x max radius */

    /* overburden (on when overburden_force > 0) */
    double overburden_force; /* N, force on each surface element = pressure x column_width */
    long n_surface;          /* surface elements flagged at the last rebuild */
    size_t *col_top;         /* per-column scratch: the surface element (colcap) */
    size_t colcap;           /* capacity of col_top */

    /* confining pressure on the free side edges (on when confining_pressure > 0) */
    double confining_pressure;  /* N/m, full lateral pressure, >= 0 */
    long confining_equil;       /* steps of equilibration: ramp 0 at half of it, 1 at its end */
    double confining_factor;    /* ramp factor of the current step, 0..1 */
    double edge_x_mid;          /* m, edge elements left of this are pushed in +x, others -x */
    long n_edge;                /* edge elements flagged at the last rebuild */
    int32_t *band_lo, *band_hi; /* per-band scratch: leftmost / rightmost element (bandcap) */
    size_t bandcap;             /* capacity of band_lo, band_hi */
} cdem_loads;

/* Gravity of magnitude `gravity` tilted by tilt_deg degrees from -y toward +x
 * (cdem_model_gravity_vector), overburden and confinement off; columns 2 x max_radius wide.
 * From the magnitude and the angle, not from a vector kept in the model, so that a model made
 * by hand (the tests') that sets its gravity has it. */
void cdem_loads_init(cdem_loads *l, double gravity, double tilt_deg, double max_radius);

/* Gravity's acceleration from now on (m/s^2, the model's frame): a mode that turns the frame
 * (bc.h, the gravity hook) sets it each step. */
void cdem_loads_set_gravity(cdem_loads *l, double gx, double gy);
void cdem_loads_free(cdem_loads *l);

/* Enables the overburden: pressure in N/m (>= 0, finite; 0 disables) on the top surface.
 * Fails with CDEM_ERR_RANGE naming surface.overburden_pressure when the value is negative or
 * not finite. */
cdem_status cdem_loads_set_overburden(cdem_loads *l, double pressure, cdem_error *err);

/* Enables the confining pressure: pressure in N/m (>= 0, finite; 0 disables) on the free side
 * edges, ramped by cdem_bc_confining_ramp(step, equil_steps) (its factor set for `step`, the
 * steps taken so far). Fails with CDEM_ERR_RANGE naming boundary.confining_pressure when the
 * value is negative or not finite. */
cdem_status cdem_loads_set_confining(cdem_loads *l, double pressure, long equil_steps, long step,
                                     cdem_error *err);

/* The confining ramp of step `step` (the stepper calls it as each step begins). */
void cdem_loads_begin_step(cdem_loads *l, long step);

/* At every list rebuild: the surface elements (overburden on) and edge elements (confinement
 * on) found again. */
cdem_status cdem_loads_after_build(cdem_loads *l, cdem_state *s, cdem_error *err);

/* Flags the surface elements now (clears CDEM_FLAG_SURFACE elsewhere): in columns of width
 * column_width from the leftmost free element, the free element with the highest centre
 * (common/surface.h, CDEM_SURFACE_BY_CENTRE). Public for tests and views. */
cdem_status cdem_loads_find_surface(cdem_loads *l, cdem_state *s, cdem_error *err);

/* Flags the edge elements now (clears CDEM_FLAG_BIAXIAL_EDGE elsewhere): per band of height
 * column_width from the lowest free centre, the leftmost and rightmost free element; sets
 * edge_x_mid to the middle of the free span. Public for tests. */
cdem_status cdem_loads_find_edges(cdem_loads *l, cdem_state *s, cdem_error *err);

/* The loads of the current step, as the force pass applies them. */
cdem_force_loads cdem_loads_of_step(const cdem_loads *l);

#endif
