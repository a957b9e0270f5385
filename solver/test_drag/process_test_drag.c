/* process_test_drag: a fixture of the tests, not a process of the model (its row in
 * common/processes.def is CDEM_TEST_PROCESS, and no parameter turns it on). A uniform drag
 * field, F = -rate m v on every free element, joined to the step through the viscous
 * module's hooks (step/viscous.h). Its folder and its row are the whole of what a process
 * needs (docs/architecture.md); tests/test_process_test_drag.c sets it up on a few elements in
 * free flight and checks their velocities against the exponential decay exp(-rate t). */
#include "process.h"
#include "viscous.h"

#include <stdio.h>

/* 1/s: the drag field's rate (a time constant of 20 s) */
#define TEST_DRAG_RATE 0.05

typedef struct {
    double rate; /* 1/s */
} drag_ctx;

static int drag_active(const cdem_params *p) {
    (void)p;
    return 0; /* a fixture: the tests add it (cdem_processes_add) */
}

static void drag_forces(void *vctx, const cdem_state *s, double *ex, double *ey) {
    const double rate = ((const drag_ctx *)vctx)->rate;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        ex[i] -= rate * s->mass[i] * s->vx[i];
        ey[i] -= rate * s->mass[i] * s->vy[i];
    }
}

static const cdem_viscous_hooks drag_hooks = {NULL, drag_forces, NULL};

static cdem_status drag_configure(void *vctx, const cdem_params *p, const cdem_model *m,
                                  cdem_integrator *it, cdem_error *err) {
    (void)p, (void)m;
    drag_ctx *c = vctx;
    c->rate = TEST_DRAG_RATE;
    return cdem_viscous_add(&it->viscous, &drag_hooks, c, err);
}

static void drag_describe(const cdem_params *p, const cdem_model *m, FILE *out) {
    (void)p, (void)m;
    fprintf(out, "\nTest drag\n  rate: %g 1/s\n", TEST_DRAG_RATE);
}

static const cdem_process_ops drag_ops = {
    .word = "test-drag",
    .state_size = sizeof(drag_ctx),
    .active = drag_active,
    .describe = drag_describe,
    .configure = drag_configure,
};

const cdem_process_ops *const cdem_process_test_drag = &drag_ops;
