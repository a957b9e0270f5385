/* viscous: see viscous.h. */
#include "viscous.h"

#include "contact.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cdem_viscous_init(cdem_viscous *v, const cdem_model *m) {
    memset(v, 0, sizeof *v);
    v->contact_damping = m->contact_damping;
    v->kn = m->kn;
}

cdem_status cdem_viscous_add(cdem_viscous *v, const cdem_viscous_hooks *hooks, void *ctx,
                             cdem_error *err) {
    if (v->n_processes >= CDEM_VISCOUS_PROCESSES)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "viscous forces: at most %d processes at once",
                         CDEM_VISCOUS_PROCESSES);
    v->hooks[v->n_processes] = hooks;
    v->ctx[v->n_processes] = ctx;
    v->n_processes++;
    return CDEM_OK;
}

void cdem_viscous_free(cdem_viscous *v) {
    if (!v)
        return;
    free(v->ex);
    free(v->ey);
    memset(v, 0, sizeof *v);
}

cdem_status cdem_viscous_after_build(cdem_viscous *v, const cdem_neighbour *nb, const cdem_state *s,
                                     cdem_error *err) {
    if (!cdem_viscous_active(v))
        return CDEM_OK;
    if (v->cap < s->n) {
        const size_t c = s->n + s->n / 2 + 16;
        double *a = realloc(v->ex, c * sizeof *a);
        if (a)
            v->ex = a;
        double *b = a ? realloc(v->ey, c * sizeof *b) : NULL;
        if (!b)
            return CDEM_FAIL(err, CDEM_ERR_NOMEM, "viscous forces: out of memory (%zu elements)",
                             c);
        v->ey = b;
        v->cap = c;
    }
    for (int k = 0; k < v->n_processes; k++)
        if (v->hooks[k]->after_build)
            CDEM_TRY(v->hooks[k]->after_build(v->ctx[k], nb, s, err));
    return CDEM_OK;
}

/* The contact dashpots over the pair list (viscous.h). */
static void contact_dashpots(const cdem_viscous *v, const cdem_neighbour *nb, const cdem_state *s) {
    const double two_zeta = 2.0 * v->contact_damping, kn = v->kn;
    const double *x = s->x, *y = s->y, *vx = s->vx, *vy = s->vy, *mass = s->mass;
    const uint32_t *flags = s->flags;
    double *ex = v->ex, *ey = v->ey;
    for (size_t p = 0; p < nb->np; p++) {
        const int32_t i = nb->pi[p], j = nb->pj[p];
        const double dx = x[j] - x[i], dy = y[j] - y[i], R = nb->R[p];
        const double r2 = dx * dx + dy * dy;
        if (!(r2 > 0.0) || (!(r2 < R * R) && !(nb->hist[p] & CDEM_PAIR_BONDED)))
            continue;
        const int bi = (flags[i] & CDEM_FLAGS_BOUNDARY) != 0;
        const int bj = (flags[j] & CDEM_FLAGS_BOUNDARY) != 0;
        const double m = bi ? mass[j] : bj ? mass[i] : mass[i] * mass[j] / (mass[i] + mass[j]);
        const double r = sqrt(r2), nx = dx / r, ny = dy / r;
        const double vn = (vx[j] - vx[i]) * nx + (vy[j] - vy[i]) * ny;
        const double f = two_zeta * sqrt(kn * m) * vn;
        ex[i] += f * nx;
        ey[i] += f * ny;
        ex[j] -= f * nx;
        ey[j] -= f * ny;
    }
}

void cdem_viscous_forces(cdem_viscous *v, const cdem_neighbour *nb, const cdem_state *s) {
    memset(v->ex, 0, s->n * sizeof *v->ex);
    memset(v->ey, 0, s->n * sizeof *v->ey);
    if (v->contact_damping > 0.0)
        contact_dashpots(v, nb, s);
    for (int k = 0; k < v->n_processes; k++)
        if (v->hooks[k]->forces)
            v->hooks[k]->forces(v->ctx[k], s, v->ex, v->ey);
}

void cdem_viscous_finish(cdem_viscous *v, cdem_state *s, int kick, double dt, double c) {
    const double hdt = 0.5 * dt;
    for (size_t i = 0; i < s->n; i++) {
        const double ex = v->ex[i], ey = v->ey[i];
        if (kick && !(s->flags[i] & CDEM_FLAGS_BOUNDARY)) {
            const double k = hdt / (s->mass[i] + c * hdt);
            s->vx[i] += k * ex;
            s->vy[i] += k * ey;
            s->fx[i] += ex - c * k * ex;
            s->fy[i] += ey - c * k * ey;
        } else {
            s->fx[i] += ex;
            s->fy[i] += ey;
        }
    }
    if (kick && dt > 0.0)
        for (int k = 0; k < v->n_processes; k++)
            if (v->hooks[k]->after_step)
                v->hooks[k]->after_step(v->ctx[k], s, dt);
}
