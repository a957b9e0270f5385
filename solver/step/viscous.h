/* viscous: the viscous forces that the pair kernel (contact.h) does not compute, added to a
 * time step by the stepper (integrate.c): the contact dashpots of physics.damping_mode =
 * contact and the processes' (a viscous continuum, solver/process/). Both need the elements'
 * mid-step velocities, as the tangential spring does, so on the steps that have them the stepper
 * drifts first, brings the pair list up to date, evaluates these forces (cdem_viscous_forces), then
 * the force pass, and adds them with the second half kick's factor (cdem_viscous_finish): with the
 * force pass's v = (m v_half + dt/2 F) / (m + c dt/2), adding E gives v += (dt/2) E / (m + c dt/2)
 * and F += E - c (dt/2) E / (m + c dt/2), the step the force pass would have made with F + E.
 * Without them (damping_mode = absolute, no process's forces) the module is off and the stepper
 * runs exactly as before: every result bit-identical.
 *
 * Contact damping: on every pair of the list that touches (r < R at the step's positions) or
 * holds an intact bond, a dashpot along the line of centres
 *     F_i = c (dv . n) n,   c = zeta 2 sqrt(Kn m_i m_j / (m_i + m_j))
 * (zeta = physics.contact_damping; a boundary element counts as infinitely heavy:
 * c = zeta 2 sqrt(Kn m_free)). It damps a contact's vibrations (elastic waves) but neither a
 * rigid motion nor a rigid rotation of a group of elements, unlike the absolute damping, whose
 * drag on every element's velocity would resist a cover moving slowly over a viscous
 * substrate far more than the substrate does (docs/solver.md, "Damping").
 * Determinism: serial sums in pair order (the pair list's slots), then each process's in its
 * own order: the same bits for any thread count. Nothing allocates in a step (buffers grow at
 * list builds).
 * The processes' forces (solver/<id>/) come through cdem_viscous_hooks: a
 * process adds its hooks and its context (cdem_viscous_add) when it is configured, and the
 * module calls them in the order they were added; it knows no process by name.
 * Ownership: cdem_viscous owns its buffers, never the state or a process's context (the
 * process's, solver/process/). Units: SI. */
#ifndef CDEM_VISCOUS_H
#define CDEM_VISCOUS_H

#include "cdem_error.h"
#include "model.h"
#include "neighbour.h"
#include "state.h"

/* A process's forces beside the pair list's (a viscous continuum). */
typedef struct {
    /* after each list build (and a checkpoint's restored list): its own structures from the
     * list and the positions of the build */
    cdem_status (*after_build)(void *ctx, const cdem_neighbour *nb, const cdem_state *s,
                               cdem_error *err);
    /* its forces of the current positions and mid-step velocities, added into ex, ey */
    void (*forces)(void *ctx, const cdem_state *s, double *ex, double *ey);
    /* after a time step dt (its kick done): its own update (e.g. its elements' area) */
    void (*after_step)(void *ctx, cdem_state *s, double dt);
} cdem_viscous_hooks;

/* The processes a step can hold at once. */
#define CDEM_VISCOUS_PROCESSES 4

typedef struct {
    double contact_damping; /* zeta, fraction of critical (0: off) */
    double kn;              /* N/m */
    int n_processes;        /* processes whose forces join the step */
    const cdem_viscous_hooks *hooks[CDEM_VISCOUS_PROCESSES];
    void *ctx[CDEM_VISCOUS_PROCESSES]; /* theirs, not owned */
    double *ex, *ey;                   /* N: this step's forces on each element */
    size_t cap;                        /* capacity of ex, ey */
} cdem_viscous;

/* Sets up the contact damping from the model (a process adds itself: cdem_viscous_add). */
void cdem_viscous_init(cdem_viscous *v, const cdem_model *m);
void cdem_viscous_free(cdem_viscous *v);

/* A process's forces join the step from now on (hooks and ctx are the process's; they must
 * outlive v). CDEM_ERR_RANGE when CDEM_VISCOUS_PROCESSES are already there. */
cdem_status cdem_viscous_add(cdem_viscous *v, const cdem_viscous_hooks *hooks, void *ctx,
                             cdem_error *err);

/* 1 when there is anything to add (contact damping or a process's forces). */
static inline int cdem_viscous_active(const cdem_viscous *v) {
    return v->contact_damping > 0.0 || v->n_processes > 0;
}

/* After each list build, and after a checkpoint's list is restored: the buffers for the
 * state's elements, and each process's after_build (e.g. its grid and its pairs). */
cdem_status cdem_viscous_after_build(cdem_viscous *v, const cdem_neighbour *nb, const cdem_state *s,
                                     cdem_error *err);

/* The forces of the current positions and velocities into ex, ey (the list current). */
void cdem_viscous_forces(cdem_viscous *v, const cdem_neighbour *nb, const cdem_state *s);

/* Adds ex, ey to the state: to fx, fy of every element and, when kick, to the velocities of
 * the free elements with the second half kick's factor for time step dt and absolute damping
 * c (see the top of this file); after a time step (dt > 0 and kick) each process's
 * after_step. */
void cdem_viscous_finish(cdem_viscous *v, cdem_state *s, int kick, double dt, double c);

#endif
