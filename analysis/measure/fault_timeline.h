/* fault_timeline: the boundary actors of a run read back from its parameters (each fault's
 * mode, where it meets the base, its dip and its window), how far each has moved, and which
 * fault zone was active in which increments, measured from the incremental strain near each
 * fault's trace (docs/analysis.md "Faults on a timeline"), so that a run of several faults
 * (docs/solver.md "Boundaries on a timeline") can be read without pictures.
 *
 * The run's boundary displacement at an increment (the clock of the windows) is
 * (step - step at the end of equilibration) x 25 dt^2 (the boundary's acceleration x dt^2,
 * solver/base/model.h), dt = time / step of the increment: the increments' net displacement
 * is the sum of the actors' and cannot be used.
 * Activity (cdem_timeline_measure): the zone of fault j is the free elements in the lower half
 * of the assembly (0 <= y <= H/2, H the highest free element top of increment 0) within `band`
 * of its trace: the line from where it meets the base up at its basal dip (a listric fault's
 * dip steepens linearly to 90 degrees at H, as the solver's curve; an irregular fault is
 * taken as straight at fault_dip), shifted with the base element just left of it (its
 * footwall's base, which another fault may carry). Its score in increment k is the mean
 * maximum shear strain of the increment alone (from increment k - 1 to k; incr-max-shear spans
 * 5 increments, as in the original program, and would smear the windows) of its zone over the
 * median of the free elements of the lower half (the increment's background: the diffuse
 * settling at the start of deformation raises both); it is active when the score is at least
 * `contrast` (default 3). An inactive fault sits inside a block that moves as one and its zone strains
 * no more than the rest.
 * Ownership: the result owns its arrays (cdem_timeline_free). Thread safety: one analysis
 * context per thread. Units: m, degrees. */
#ifndef CDEM_FAULT_TIMELINE_H
#define CDEM_FAULT_TIMELINE_H

#include "analysis.h"
#include "params.h"

typedef struct {
    char section[20]; /* "[boundary]", "[boundary.2]" ... */
    cdem_mode mode;   /* its mode */
    int fault;        /* 1: a fault mode (planar, listric, irregular): it has a trace */
    int listric;      /* 1: listric-fault (its dip steepens to 90 degrees at the top) */
    double x_base;    /* m, where the fault meets the base (fault_location x width) */
    double dip_deg;   /* degrees, its (basal) dip */
    double start;     /* m of the run's boundary displacement before it moves */
    double stop;      /* m of it at which it stops; 0: the end of the run */
} cdem_timeline_actor;

/* The actors of run parameters p into out (CDEM_BOUNDARY_ACTORS entries); their number. */
int cdem_timeline_actors(const cdem_params *p, cdem_timeline_actor *out);

/* The run's boundary displacement (m) at increment index of a (0 before the end of
 * equilibration, or when it is not known). */
double cdem_timeline_run_displacement(const cdem_analysis *a, size_t index);

/* The displacement (m) actor t has made when the run's boundary has moved `run` m. */
double cdem_timeline_actor_displacement(const cdem_timeline_actor *t, double run);

typedef struct {
    double band;     /* m, half width of a fault's zone; <= 0: 2 x the largest free radius,
                        at most a quarter of the smallest distance between two faults */
    double contrast; /* the activity threshold (above), > 1; default 3 */
} cdem_timeline_options;

typedef struct {
    int n_actors; /* faults measured (the actors with a trace) */
    cdem_timeline_actor actor[CDEM_BOUNDARY_ACTORS];
    size_t n_inc;          /* deformation increments measured */
    int *number;           /* n_inc increment numbers */
    double *run;           /* n_inc run displacements (m) */
    double *score;         /* n_inc x n_actors, row-major: the zone's mean incr-max-shear */
    unsigned char *active; /* n_inc x n_actors: 1 active */
    double band;           /* m, the band used */
    /* per actor: the first and last increment number measured active (-1: never) and the
     * first and last increment number whose interval its window overlaps (-1: none) */
    int first_active[CDEM_BOUNDARY_ACTORS], last_active[CDEM_BOUNDARY_ACTORS];
    int first_window[CDEM_BOUNDARY_ACTORS], last_window[CDEM_BOUNDARY_ACTORS];
} cdem_timeline_result;

void cdem_timeline_default_options(cdem_timeline_options *o);

/* Measures every fault actor of a's run over its deformation increments. CDEM_ERR_NOTFOUND
 * when the run has no fault actor or no deformation increment. */
cdem_status cdem_timeline_measure(cdem_analysis *a, const cdem_timeline_options *o,
                                  cdem_timeline_result *res, cdem_error *err);

void cdem_timeline_free(cdem_timeline_result *res);

#endif
