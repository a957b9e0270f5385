/* model: the quantities derived from the parameters (as in the original program): element radii and
 * masses, spring and damping constants, time step, boundary speed, step counts and the
 * display-increment schedule. Pure functions of cdem_params and of what the boundary mode
 * decides (cdem_model_mode); the solver, the summary and the tests all use these, so a
 * constant is computed in exactly one place.
 *
 * Increment schedule (documented in docs/format.md and docs/parameters.md):
 *  - increment 0 is the assembly at the start of equilibration;
 *  - equilibration has n_equil = max(1, round(equil_steps / display_steps)) increments,
 *    evenly spaced, so increment n_equil falls exactly on the last equilibration step;
 *  - deformation increments follow every display_steps steps, and a last one at the final
 *    step: n_total = n_equil + ceil((total_steps - equil_steps) / display_steps).
 *  For the default model: 56 in equilibration, 282 in all.
 * Units: SI. Thread safety: pure functions. */
#ifndef CDEM_MODEL_H
#define CDEM_MODEL_H

#include "params.h"
#include "state.h"

#include <stdint.h>

#define CDEM_NUM_RADII        4
#define CDEM_PREGROWTH_LAYERS 24

/* The radius classes' number shares, smallest first (4:3:2:1, the original program's): the
 * assembly's composition (solver/packing/assembly.c) and the deposits' draws
 * (solver/packing/sediment.c). An initializer for an int array of CDEM_NUM_RADII, and the shares'
 * sum. */
#define CDEM_RADIUS_SHARES                                                                         \
    { 4, 3, 2, 1 }
#define CDEM_RADIUS_SHARES_TOTAL 10

/* Seconds in a (Julian) year: the geological times of the processes that map the run's
 * clock to them (a viscous substrate's rate in mm per year, a tilt's history in Myr). */
#define CDEM_SECONDS_PER_YEAR (365.25 * 86400.0)

/* Boundary speed of the original program: v = CDEM_BOUNDARY_ACCEL * dt, in m/s. */
#define CDEM_BOUNDARY_ACCEL 25.0

/* What the boundary mode decides about the model before the assembly exists (its derive
 * hook, solver/modes/bc.h). A mode without the hook has cdem_model_mode_default's: gravity
 * acts, one boundary moves at the boundary speed, the base as assembly.base_spacing says, no
 * input besides the parameter file. The texts are static or point into the parameters. */
typedef struct {
    const char *gravity_off; /* NULL: physics.gravity acts; else why it does not (summary) */
    int moving_boundaries;   /* boundaries moving at the boundary speed, >= 0: the total
                                displacement counts each; 0: none moves, and the display
                                interval is then in s */
    const char *still;       /* with 0 moving boundaries: what happens instead (summary) */
    double base_spacing;     /* > 0: the base's centre spacing in wall radii, whatever
                                assembly.base_spacing says; 0: the parameter's */
    double base_beyond_left, base_beyond_right; /* the base runs on past the left / right
                                wall by this many assembly widths (>= 0; repose: the pile
                                comes to rest on it) */
    const char *input;      /* a file the run reads besides the parameter file, or NULL */
    const char *input_what; /* how messages name it */
    double gravity_tilt;    /* degrees, in (-90, 90): gravity's angle from -y, positive toward
                               +x (the model's frame tilted with a margin that dips toward +x);
                               0: straight down. A mode may turn it further step by step
                               (bc.h, the gravity hook) */
} cdem_model_mode;

/* The mode part of a mode without a derive hook. */
static inline cdem_model_mode cdem_model_mode_default(void) {
    return (cdem_model_mode){.gravity_off = NULL,
                             .moving_boundaries = 1,
                             .still = NULL,
                             .base_spacing = 0.0,
                             .base_beyond_left = 0.0,
                             .base_beyond_right = 0.0,
                             .input = NULL,
                             .input_what = NULL,
                             .gravity_tilt = 0.0};
}

/* Gravity's acceleration (m/s^2) in the model's frame for a tilt of tilt_deg degrees from -y
 * toward +x: (g sin t, -g cos t). A tilt of 0 gives exactly (+0, -g), so that an untilted run
 * has the bits of gravity as a scalar along -y (force_pairs.h, the finish). */
void cdem_model_gravity_vector(double g, double tilt_deg, double *gx, double *gy);

typedef struct {
    double radius[CDEM_NUM_RADII]; /* m, ascending */
    double mass[CDEM_NUM_RADII];   /* kg per metre of thickness, density * pi r^2 */
    double min_mass;               /* kg, smallest mass of any element (light interval and
                                      the processes' own elements included) */
    const char *lightest_process;  /* the word of the process whose own elements are the
                                      lightest of the processes' (NULL: no process has
                                      elements of its own) */
    double lightest_process_mass;  /* kg, the mass of its smallest element class */
    double average_radius;         /* m, mean of the four radii */
    double max_radius;             /* m */
    double kn, ks;                 /* N/m, normal and shear spring stiffness */
    double damping;                /* N s/m, viscous force = -damping * velocity (absolute
                                      damping; with physics.damping_mode = contact only on the
                                      steps of equilibration and sediment settling) */
    double contact_damping;        /* contact dashpots as a fraction of critical (0 with
                                      damping_mode = absolute) */
    double dt;                     /* s, 0.25 sqrt(min_mass / kn) */
    double boundary_speed;         /* m/s, CDEM_BOUNDARY_ACCEL * dt */
    double displacement_per_step;  /* m, boundary_speed * dt */
    double gravity;                /* m/s^2, the magnitude actually applied (0 when the mode
                                      turns it off); its direction: mode.gravity_tilt */
    long elements_estimated;       /* free elements the assembly will hold, about
                                      (cdem_model_estimate_elements): the memory the run needs
                                      is checked from it before anything is built */
    double width_m, height_m;      /* assembly size in m */
    long equil_steps;              /* time steps of equilibration, round(equilibration / dt) */
    long total_steps;              /* time steps of the whole run, round(runtime / dt) */
    double display_steps;          /* time steps between increments (not rounded) */
    int n_increments_equil;        /* increment number at the end of equilibration */
    int n_increments_total;        /* number of the last increment */
    double total_displacement;     /* m, boundary displacement expected over the run */
    double sediment_interval;      /* m of boundary displacement, 30 * display interval */
    long sediment_steps;           /* steps between sediment events */
    long settling_steps;           /* steps of settling after each sediment event */
    double sea_level_factor;       /* 0, 0.25, 0.5, 0.75, 1.0 */
    cdem_model_mode mode;          /* what the boundary mode decided (its derive hook) */
    uint32_t moving_flag;          /* the flag of the elements the boundary actor moves:
                                      CDEM_FLAG_MOVING (the run's model, its first actor), else
                                      CDEM_FLAG_ACTOR_MOVING(N) (bc.h, cdem_bc_moving_flag) */
    int composed;                  /* 1: the actor is one of several (bc.h, "Boundaries compose":
                                      a composing mode then adds its velocities to the
                                      others'); 0: alone */
} cdem_model;

/* Computes every derived quantity from the parameters and the mode's part `mode` (its derive
 * hook's; NULL: cdem_model_mode_default). Fails (CDEM_ERR_RANGE) only if p is unusable (e.g.
 * non-positive sizes); run cdem_run_validate first for user-facing checks. The solver calls
 * it through cdem_bc_derive_model (solver/modes/bc.h), which asks p's mode for its part. */
cdem_status cdem_model_derive(const cdem_params *p, const cdem_model_mode *mode, cdem_model *m,
                              cdem_error *err);

/* Time step at which increment k (0..n_increments_total) is written. */
long cdem_model_increment_step(const cdem_model *m, int k);

/* The deformation step (counted without settling steps) at which an inverting mode turns:
 * inversion_percent of the deformation steps; past the last step when inversion is off. */
long cdem_model_inversion_step(const cdem_params *p, const cdem_model *m);

/* Number of sediment deposits the run makes when sedimentation is on (0 when it is off):
 * one every sediment_steps run steps after the equilibration, each one whose settling ends
 * by the last step (cdem_sediment_due's schedule; a settling never outlasts the interval,
 * the parameter rules refuse that). Each takes settling_steps without boundary motion. */
long cdem_model_sediment_events(const cdem_params *p, const cdem_model *m);

/* Rough element count of the assembly before it is generated (from the packing density
 * of the original program: 2121 for 10 x 5 units), for summaries made without a solver. */
long cdem_model_estimate_elements(const cdem_params *p);

#endif
