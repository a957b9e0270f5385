/* tilt: the regional tilt, a tilting margin (issue 47, item 3; docs/solver.md, "Regional
 * tilt"). The whole model, box and base with it, rotates rigidly relative to gravity by
 * tilt.angle over a window of the deformation: the model's frame stays the box's and gravity
 * turns in it, from -y toward +x for a positive angle, at a constant rate (a tilting table, as
 * in the analogue experiments of gravity gliding; docs/solver.md says which). It composes with
 * any boundary mode: it turns whatever gravity the mode gives (bc.h, the gravity hook), after
 * the mode. Its clock is the boundaries': deformation steps (model time after equilibration),
 * given in seconds so that it means the same with every mode, moving boundaries or not.
 * The process (tilt.c) is a plug-in (solver/process/process.h): its gravity hook, its rules
 * and its summary section. Nothing of it evolves but gravity's direction, which the stepper
 * checkpoints; the angle of a step is a function of the step, so a resumed run is
 * bit-identical. Thread safety: pure functions. Units: degrees, s, steps. */
#ifndef CDEM_TILT_H
#define CDEM_TILT_H

#include "model.h"
#include "params.h"

/* The tilt's history in deformation steps. */
typedef struct {
    double angle; /* degrees at the end of the tilting (tilt.angle) */
    long k_begin; /* deformation steps before it tilts (>= 0) */
    long k_end;   /* the deformation step at which the tilt is complete, > k_begin */
    long k_run;   /* the run's deformation steps */
} cdem_tilt_schedule;

/* The schedule of p on the model m: k_begin = round(onset / dt), k_end = k_begin +
 * max(1, round(duration / dt)) or, with duration = rest, the run's last deformation step. */
void cdem_tilt_schedule_of(const cdem_params *p, const cdem_model *m, cdem_tilt_schedule *t);

/* Degrees the model has turned by the end of deformation step k (0 before the window, linear
 * in k in it, the full angle after). */
double cdem_tilt_angle_at(const cdem_tilt_schedule *t, long k);

/* The tilt's parameter rules (the process's rules hook): the window within the run's
 * deformation; a mode that turns gravity off; the mode's tilt plus this one within 90
 * degrees; the surface processes whose levels and loads are horizontal in the model's frame
 * (sedimentation, erosion, the overburden), which a tilt would make wrong, refused. */
void cdem_tilt_rules(const cdem_params *p, cdem_rule_log *log);

#endif
