/* run_output: what a run writes into its file besides checkpoints (run_ctx.h): the
 * increments (after the erosion due before them, with the stress when asked; before each,
 * the processes' increment hooks: a viscous process's elements get their continuum stress,
 * and its measures are tracked for its last log line), the time-series samples (kinetic
 * energy, contacts, bonds, boundary and base forces, the mode's measures, the processes'
 * columns) and the summary text. */
#include "run_ctx.h"

#include "stress.h"
#include "summary.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Erosion before an increment of the deformation phase: every free element whose centre is
 * above erosion_y is removed (integrator removal path), the count logged. */
static cdem_status erode(run_ctx *r, cdem_error *err) {
    if (!r->p->erosion || !isfinite(r->erosion_y) || r->step <= r->m.equil_steps)
        return CDEM_OK;
    long count = 0;
    CDEM_TRY(cdem_integrator_erode(&r->it, &r->s, r->erosion_y, &count, err));
    r->eroded += count;
    if (run_logging(r) && count > 0) {
        run_end_progress_line(r);
        fprintf(r->opt->log,
                "cdem-run: erosion removed %ld elements above y = %.6g m before increment %d at "
                "step %ld (%ld eroded so far)\n",
                count, r->erosion_y, r->next_inc, r->step, r->eroded);
    }
    return CDEM_OK;
}

cdem_status run_write_increment(run_ctx *r, cdem_error *err) {
    CDEM_TRY(erode(r, err));
    if (r->p->calculate_stress)
        CDEM_TRY(cdem_stress_compute(&r->it.nb, &r->s, err));
    cdem_processes_increment(&r->procs, &r->s); /* their stress and measures (process.h) */
    cdem_increment_info inf;
    memset(&inf, 0, sizeof inf);
    inf.number = r->next_inc;
    inf.step = r->step;
    inf.time = (double)r->step * r->m.dt;
    inf.phase = run_phase_of(r, r->step);
    inf.net_displacement = cdem_bc_net_displacement(&r->bc);
    inf.sea_level = cdem_sediment_sea_level(&r->sed, r->step);
    inf.n_elements = (int64_t)r->s.n;
    inf.has_stress = r->s.has_stress;
    cdem_bc_measure(&r->bc, &r->s, r->step, 0, &inf.axial_strain, &inf.differential_stress);
    if (r->w)
        CDEM_TRY(cdem_h5_writer_write_increment(r->w, &inf, &r->s, err));
    r->next_inc++;
    r->last_written_step = r->step;
    return CDEM_OK;
}

cdem_status run_write_sample(run_ctx *r, cdem_error *err) {
    cdem_series_sample q;
    memset(&q, 0, sizeof q);
    q.step = r->step;
    q.time = (double)r->step * r->m.dt;
    const cdem_state *s = &r->s;
    double ke = 0.0, bfx = 0.0, bfy = 0.0, gfx = 0.0, gfy = 0.0;
    double wall[2][2] = {{0.0, 0.0}, {0.0, 0.0}}; /* [left, right][x, y] */
    for (size_t i = 0; i < s->n; i++) {           /* serial, fixed order: reproducible sums */
        const uint32_t f = s->flags[i];
        if (!(f & CDEM_FLAGS_BOUNDARY)) {
            ke += 0.5 * s->mass[i] * (s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i]);
            continue;
        }
        if (f & CDEM_FLAG_MOVING) {
            bfx += s->fx[i];
            bfy += s->fy[i];
        } else if ((f & CDEM_FLAG_WALL) && s->y[i] <= r->base_tol_y) {
            gfx += s->fx[i];
            gfy += s->fy[i];
        }
        /* lateral walls, fixed or moving: wall elements off the base row (the biaxial
         * platens are base rows), not faces of a fault */
        if ((f & (CDEM_FLAG_WALL | CDEM_FLAG_BASE | CDEM_FLAG_FAULT | CDEM_FLAG_MYLAR |
                  CDEM_FLAG_FOOTWALL)) == CDEM_FLAG_WALL &&
            s->y[i] > r->base_tol_y) {
            double *side = wall[s->x[i] < r->wall_mid_x ? 0 : 1];
            side[0] += s->fx[i];
            side[1] += s->fy[i];
        }
    }
    long contacts = 0, bonds = 0;
    cdem_integrator_count(&r->it, &contacts, &bonds);
    q.kinetic_energy = ke;
    q.contacts = contacts;
    q.bonds = bonds;
    q.n_elements = (int64_t)s->n;
    q.net_displacement = cdem_bc_net_displacement(&r->bc);
    q.boundary_force_x = bfx;
    q.boundary_force_y = bfy;
    q.base_force_x = gfx;
    q.base_force_y = gfy;
    q.left_wall_force_x = wall[0][0];
    q.left_wall_force_y = wall[0][1];
    q.right_wall_force_x = wall[1][0];
    q.right_wall_force_y = wall[1][1];
    q.sea_level = cdem_sediment_sea_level(&r->sed, r->step);
    cdem_series_processes_absent(&q); /* the columns of a process that is off */
    cdem_processes_sample(&r->procs, s, &q);
    cdem_bc_measure(&r->bc, s, r->step, 1, &q.axial_strain, &q.differential_stress);
    return r->w ? cdem_h5_writer_append_series(r->w, &q, err) : CDEM_OK;
}

/* The element count of increment 0 (docs/format.md, "Counting"): free elements and the
 * rest (walls, fault ramps, mylar, footwall display), after the mode has added its own. */
void run_count_kinds(const cdem_state *s, long *n_free, long *n_boundary) {
    *n_free = *n_boundary = 0;
    for (size_t i = 0; i < s->n; i++)
        ++*((s->flags[i] & CDEM_FLAGS_BOUNDARY) ? n_boundary : n_free);
}

cdem_status run_make_summary(run_ctx *r, cdem_error *err) {
    char *text = NULL;
    long n_free, n_boundary;
    run_count_kinds(&r->s, &n_free, &n_boundary);
    CDEM_TRY(cdem_summary_text(r->p, &r->m, n_free, n_boundary, 0, &text, err));
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f) {
        free(text);
        return CDEM_FAIL(err, CDEM_ERR_NOMEM, "out of memory for the summary text");
    }
    fputs(text, f);
    const size_t tl = strlen(text);
    if (tl == 0 || text[tl - 1] != '\n')
        fputc('\n', f);
    cdem_bc_view(&r->bc, f);
    fprintf(f,
            "Solver: velocity Verlet, dt %.6g s, Verlet-list skin %.4g m, %s contacts; "
            "cohesion/bonds created for touching pairs at the end of equilibration%s.\n",
            r->m.dt, r->it.nb.skin,
            r->p->material == CDEM_MATERIAL_BONDED ? "bonded" : "frictional-cohesive",
            r->p->sedimentation ? " and for the pairs of each sediment deposit at the end of its "
                                  "settling (settling steps count in the runtime; boundaries "
                                  "still)"
                                : "");
    fclose(f);
    free(text);
    r->summary = buf;
    return CDEM_OK;
}
