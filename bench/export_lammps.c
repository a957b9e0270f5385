/* export_lammps: the cdem side of the side-by-side benchmark against LAMMPS
 * (bench/lammps_bench.sh). Builds the default assembly (optionally wider / half radii),
 * equilibrates it with the solver (walls still, as cdem-run's equilibration), then
 *   1. zeroes every tangential spring (a LAMMPS data file cannot carry shear history, so
 *      both codes start from unloaded tangential springs) and recomputes the forces;
 *   2. writes OUTDIR/cdem.data (LAMMPS atom_style sphere: id type diameter density x y z,
 *      plus Velocities; type 1 = free element, type 2 = boundary element, frozen in LAMMPS)
 *      and OUTDIR/cdem_consts.in (LAMMPS variables: Kn, Ks, mu, damping, g, dt, skin);
 *   3. runs NPHYS static steps (bc NULL: walls still, no cohesion, like the LAMMPS run) and
 *      writes OUTDIR/cdem_phys.dump (ITEM: ATOMS id type x y radius) and prints the
 *      kinetic energy of the free elements (physics check; overlaps by lammps_overlap.py);
 *   4. continues with REPS timed runs of NTIME steps for 1 and then 2 OpenMP threads and
 *      prints one "CDEM_TIME threads T rep R ... seconds S ... cpu_seconds C" line per run
 *      (C: CPU time of all threads, the steadier figure when other jobs share the cores).
 * LAMMPS masses: the data file's density is m / (4/3 pi r^3), because LAMMPS (29 Sep 2021)
 * computes the mass of atom_style sphere from the 3-D volume even in 2-D; the bench script
 * checks that LAMMPS's total free mass equals ours.
 * Usage: export_lammps OUTDIR [width_units=10] [half_radii=0] [nphys=2000] [ntime=5000]
 *                      [reps=3] [equil_steps=model] [height_units=5] */
#include "assembly.h"
#include "bc.h"
#include "integrate.h"
#include "model.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double cpu_s(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int fail(const cdem_error *err) {
    fprintf(stderr, "export_lammps: %s\n", err->msg);
    return 1;
}

static int is_boundary(uint32_t f) {
    return (f & CDEM_FLAGS_BOUNDARY) != 0;
}

static int write_data(const char *path, const cdem_state *s, double margin) {
    FILE *f = fopen(path, "w");
    if (!f)
        return 1;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        xmin = fmin(xmin, s->x[i] - s->radius[i]);
        xmax = fmax(xmax, s->x[i] + s->radius[i]);
        ymin = fmin(ymin, s->y[i] - s->radius[i]);
        ymax = fmax(ymax, s->y[i] + s->radius[i]);
    }
    fprintf(f, "cdem-c settled packing (export_lammps)\n\n%zu atoms\n2 atom types\n\n", s->n);
    fprintf(f,
            "%.17g %.17g xlo xhi\n%.17g %.17g ylo yhi\n%.17g %.17g zlo zhi\n\nAtoms # sphere\n\n",
            xmin - margin, xmax + margin, ymin - margin, ymax + 4.0 * margin, -margin, margin);
    for (size_t i = 0; i < s->n; i++) {
        const double r = s->radius[i];
        const double m = s->mass[i] > 0.0 ? s->mass[i] : 1.0;
        fprintf(f, "%d %d %.17g %.17g %.17g %.17g 0\n", (int)s->id[i] + 1,
                is_boundary(s->flags[i]) ? 2 : 1, 2.0 * r, m / (4.0 / 3.0 * M_PI * r * r * r),
                s->x[i], s->y[i]);
    }
    fprintf(f, "\nVelocities\n\n");
    for (size_t i = 0; i < s->n; i++)
        fprintf(f, "%d %.17g %.17g 0 0 0 0\n", (int)s->id[i] + 1,
                is_boundary(s->flags[i]) ? 0.0 : s->vx[i],
                is_boundary(s->flags[i]) ? 0.0 : s->vy[i]);
    return fclose(f) != 0;
}

static int write_dump(const char *path, const cdem_state *s) {
    FILE *f = fopen(path, "w");
    if (!f)
        return 1;
    fprintf(f, "ITEM: ATOMS id type x y radius\n");
    for (size_t i = 0; i < s->n; i++)
        fprintf(f, "%d %d %.17g %.17g %.17g\n", (int)s->id[i] + 1, is_boundary(s->flags[i]) ? 2 : 1,
                s->x[i], s->y[i], s->radius[i]);
    return fclose(f) != 0;
}

static void free_stats(const cdem_state *s, double *ke, double *mass, size_t *nfree) {
    double k = 0.0, m = 0.0;
    size_t c = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (is_boundary(s->flags[i]))
            continue;
        k += 0.5 * s->mass[i] * (s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i]);
        m += s->mass[i];
        c++;
    }
    *ke = k;
    *mass = m;
    *nfree = c;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: export_lammps OUTDIR [width] [half_radii] [nphys] [ntime] [reps] "
                        "[equil_steps] [height]\n");
        return 2;
    }
    const char *dir = argv[1];
    cdem_params p;
    cdem_params_defaults(&p);
    if (argc > 2)
        p.width = atof(argv[2]);
    if (argc > 3)
        p.half_radii = atoi(argv[3]);
    if (argc > 8)
        p.height = atof(argv[8]);
    const long nphys = argc > 4 ? atol(argv[4]) : 2000;
    const long ntime = argc > 5 ? atol(argv[5]) : 5000;
    const int reps = argc > 6 ? atoi(argv[6]) : 3;
    cdem_model m;
    cdem_error err;
    int rc = 1;
    cdem_state s = {0};
    cdem_assembly_info info;
    cdem_integrator it = {0};
    if (cdem_bc_derive_model(&p, &m, &err) || cdem_state_init(&s, 4096, 0, &err) ||
        cdem_assembly_build(&p, &m, &s, &info, &err) || cdem_integrator_init(&it, &p, &m, &err)) {
        rc = fail(&err);
        goto done;
    }
    cdem_integrator_enable_escape(&it);
    it.unstable_guard = 1;                                                     /* as cdem-run */
    const long equil = argc > 7 && argv[7][0] ? atol(argv[7]) : m.equil_steps; /* "": model */
    double t0 = now_s();
    for (long k = 0; k < equil; k++)
        if (cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err)) {
            rc = fail(&err);
            goto done;
        }
    const double tequil = now_s() - t0;

    /* identical start: no shear history (LAMMPS cannot read it), forces recomputed */
    for (size_t q = 0; q < it.nb.np; q++)
        it.nb.xs[q] = 0.0;
    if (cdem_integrator_prime(&it, &s, &err)) {
        rc = fail(&err);
        goto done;
    }

    char path[4096];
    snprintf(path, sizeof path, "%s/cdem.data", dir);
    if (write_data(path, &s, 4.0 * m.max_radius)) {
        fprintf(stderr, "export_lammps: cannot write %s\n", path);
        rc = 1;
        goto done;
    }
    snprintf(path, sizeof path, "%s/cdem_consts.in", dir);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "export_lammps: cannot write %s\n", path);
        rc = 1;
        goto done;
    }
    /* the default model uses one friction for every class; the LAMMPS pair style has one */
    fprintf(f,
            "variable Kn equal %.17g\nvariable Ks equal %.17g\nvariable mu equal %.17g\n"
            "variable mu_wall equal %.17g\nvariable gvisc equal %.17g\nvariable grav equal %.17g\n"
            "variable dt equal %.17g\nvariable skin equal %.17g\n",
            it.law.kn, it.law.ks, it.law.friction[CDEM_CLASS_ELEMENT],
            it.law.friction[CDEM_CLASS_WALL], it.damping, it.loads.gravity, it.dt, it.nb.skin);
    fclose(f);

    double ke, mass;
    size_t nfree;
    free_stats(&s, &ke, &mass, &nfree);
    printf("CDEM_EXPORT N %zu free %zu boundary %zu equil_steps %ld equil_s %.2f free_mass %.17g "
           "ke0 %.6g skin %g dt %g\n",
           s.n, nfree, s.n - nfree, equil, tequil, mass, ke, it.nb.skin, it.dt);
    const long b0 = it.nb.n_builds;
    for (long k = 0; k < nphys; k++)
        if (cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err)) {
            rc = fail(&err);
            goto done;
        }
    free_stats(&s, &ke, &mass, &nfree);
    printf("CDEM_PHYS steps %ld ke %.6g builds %ld removed %ld\n", nphys, ke, it.nb.n_builds - b0,
           it.removal.n_removed);
    snprintf(path, sizeof path, "%s/cdem_phys.dump", dir);
    if (write_dump(path, &s)) {
        fprintf(stderr, "export_lammps: cannot write %s\n", path);
        rc = 1;
        goto done;
    }
    for (int threads = 1; threads <= 2; threads++) {
        omp_set_num_threads(threads);
        /* loops shorter than it.par_min stay serial (as in cdem-run), so the default model
         * runs serially with 2 threads too; the half-radii and larger models are threaded */
        for (int r = 1; r <= reps; r++) {
            const long b1 = it.nb.n_builds;
            const double t1 = now_s(), u1 = cpu_s();
            for (long k = 0; k < ntime; k++)
                if (cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err)) {
                    rc = fail(&err);
                    goto done;
                }
            const double t2 = now_s(), u2 = cpu_s();
            printf("CDEM_TIME threads %d rep %d N %zu steps %ld seconds %.4f builds %ld "
                   "cpu_seconds %.4f\n",
                   threads, r, s.n, ntime, t2 - t1, it.nb.n_builds - b1, u2 - u1);
            fflush(stdout);
        }
    }
    rc = 0;
done:
    cdem_integrator_free(&it);
    cdem_state_free(&s);
    return rc;
}
