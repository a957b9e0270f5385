/* salt_cells: the salt's validation set-ups, built by hand around the solver's integrator (the
 * product's code path: the assembly, the salt module, the stepper), for tests/test_salt.c
 * (short versions, in make test) and its long versions (CDEM_SALT_VALIDATE=1, make validate).
 *
 * Simple shear (Couette). The assembly of an 8 x 2 km box (default radii) with every free
 * element salt, a top plate of wall elements (base class: salt.base_contact) laid on the
 * packing, gravity off, the lateral walls free slip (salt.wall_contact). The plate moves at U to
 * the right; the lateral walls are hinged: each of their elements moves at U (y - y_b) / H, so the
 * box is a simple-shear box whose side walls follow the affine profile (cdem-c has no periodic
 * boundaries). With open_ends (make validate's long cells) the lateral walls are left out and
 * the box's ends are free: hinged free-slip walls, which hold the salt by their pairs' repulsion
 * alone, make its J run away after about 500,000 steps (docs/solver.md 9.5), and gravity is off,
 * so the salt stays in the box without them.
 * The salt starts with the affine velocity profile and is sheared to `strain`; over
 * the second half the shear stress is measured (a) on the plate, tau = -sum fx / L, and (b) as the
 * mean continuum shear stress of the salt elements of the middle half of the box (x from W/4 to
 * 3W/4); the rate as U / H (nominal) and as the slope of the mean velocity profile over the middle
 * 60 % of the gap (bulk). eta = tau / rate, against the model's set viscosity.
 *
 * Gravity current (Huppert 1982). A block of salt (the lower part of an assembly, the rest
 * removed) against the left wall (free slip: salt.wall_contact = free-slip) on the no-slip
 * base of a long box, gravity on, released at t = 0; the front x_N(t) is where a small
 * fraction of the salt's material area lies beyond x, scaled by Huppert's profile
 * (huppert_front).
 * Header-only: the fixtures are static functions of the test file that includes it. */
#ifndef CDEM_TESTS_SALT_CELLS_H
#define CDEM_TESTS_SALT_CELLS_H

#include "assembly.h"
#include "integrate.h"
#include "model.h"
#include "params.h"
#include "salt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The parameters of the salt's cells: the default model with salt on and contact damping. */
__attribute__((unused)) static cdem_params salt_cell_params(double width_km, double height_km,
                                                            int half_radii) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.width = width_km;
    p.height = height_km;
    p.half_radii = half_radii;
    p.salt_layer = CDEM_SALT_BASAL;
    p.damping_mode = CDEM_DAMPING_CONTACT;
    p.mode = CDEM_MODE_DETACHMENT;
    return p;
}

/* A cell: the model, the state, the stepper, what the placement measured. */
typedef struct {
    cdem_params p;
    cdem_model m;
    cdem_salt_model sm; /* the salt's constants (cdem_salt_model_derive) */
    cdem_state s;
    cdem_integrator it;
    cdem_salt_layer layer;
    cdem_salt salt;     /* the module, joined to it.viscous (cdem_salt_join) */
    double y_base, gap; /* m: the base's surface, the salt's height */
} salt_cell;

/* Builds the assembly of p, makes its free elements salt (J = j0; those above y_cut removed,
 * and those right of x_cut), measures the salt over region_area (0: the box it fills) and sets
 * the stepper up. */
__attribute__((unused)) static int salt_cell_open(salt_cell *c, const cdem_params *p, double j0,
                                                  double x_cut, double y_cut, double region_area,
                                                  cdem_error *err) {
    memset(c, 0, sizeof *c);
    c->p = *p;
    if (cdem_model_derive(&c->p, NULL, &c->m, err) != CDEM_OK ||
        cdem_salt_model_derive(&c->p, &c->m, &c->sm, err) != CDEM_OK)
        return 0;
    if (cdem_state_init(&c->s, 1024, 1, err) != CDEM_OK)
        return 0;
    if (cdem_assembly_build(&c->p, &c->m, &c->s, NULL, err) != CDEM_OK)
        return 0;
    unsigned char *keep = malloc(c->s.n);
    double top = 0.0, right = 0.0;
    for (size_t i = 0; i < c->s.n; i++) {
        keep[i] = 1;
        if (c->s.flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        if (c->s.y[i] > y_cut || c->s.x[i] > x_cut) {
            keep[i] = 0;
            continue;
        }
        int cls = 0;
        while (cls + 1 < CDEM_NUM_RADII && c->s.radius[i] > c->m.radius[cls])
            cls++;
        c->s.flags[i] |= CDEM_FLAG_SALT;
        c->s.mass[i] = c->sm.mass[cls];
        c->s.area_ratio[i] = j0;
        top = fmax(top, c->s.y[i] + c->s.radius[i]);
        right = fmax(right, c->s.x[i] + c->s.radius[i]);
    }
    cdem_state_compact(&c->s, keep, NULL);
    free(keep);
    c->y_base = 0.0; /* the base discs' tops (assembly.c: centres at -rw) */
    c->gap = top - c->y_base;
    c->layer.band_lo = c->y_base;
    c->layer.band_hi = top;
    if (cdem_salt_measure(&c->s, region_area > 0.0 ? region_area : right * c->gap, c->sm.reach,
                          &c->layer, err) != CDEM_OK)
        return 0;
    if (cdem_integrator_init(&c->it, &c->p, &c->m, err) != CDEM_OK)
        return 0;
    if (cdem_salt_configure(&c->salt, &c->m, &c->sm, &c->p, &c->layer, c->it.nb.skin, err) !=
            CDEM_OK ||
        cdem_salt_join(&c->salt, &c->it.viscous, err) != CDEM_OK)
        return 0;
    c->it.damping_factor = 0.0; /* the deformation steps of damping_mode = contact */
    c->it.equilibrating = 0;
    return 1;
}

__attribute__((unused)) static void salt_cell_close(salt_cell *c) {
    cdem_integrator_free(&c->it);
    cdem_salt_free(&c->salt);
    cdem_state_free(&c->s);
}

/* What a Couette run measured. */
typedef struct {
    double eta_set;                 /* Pa s, the model's viscosity */
    double rate_nominal, rate_bulk; /* 1/s */
    double tau_plate, tau_salt;     /* Pa */
    double tau_base, tau_walls;     /* Pa: the base's and the hinged walls' x force / W (checks) */
    double area_change;             /* largest |salt area / initial - 1| */
    long steps, elements;
} couette_result;

/* Sorts the elements of the shear cell's walls: 1 plate, 2 hinged lateral wall, 0 other. */
static int couette_wall_kind(const cdem_state *s, size_t i, double gap) {
    if (!(s->flags[i] & (CDEM_FLAGS_BOUNDARY | CDEM_FLAG_SALT)))
        return 1; /* a plate of cover elements */
    if (!(s->flags[i] & CDEM_FLAG_WALL))
        return 0;
    if (s->flags[i] & CDEM_FLAG_MOVING)
        return 1;
    return s->y[i] > 0.0 && s->y[i] < gap + 1.0 ? 2 : 0;
}

/* Simple shear at plate speed U to `strain` (see the top). J starts at 1 / (1 + P / K) for a
 * confining pressure P. cover_plate: the plate's elements are free (cover) elements whose motion
 * the cell imposes each step, so that the salt module couples them as cover, not as a
 * prescribed-velocity boundary. open_ends: no lateral walls (see the top). Returns 0 with err
 * set when the set-up or a step fails. */
__attribute__((unused)) static int couette_run(double U, double strain, double confining,
                                               int cover_plate, int open_ends, couette_result *out,
                                               cdem_error *err) {
    memset(out, 0, sizeof *out);
    cdem_params p = salt_cell_params(8.0, 2.0, 0);
    if (getenv("SALT_GRID"))
        p.salt_grid_spacing = atof(getenv("SALT_GRID"));
    if (getenv("SALT_HALF"))
        p.half_radii = 1;
    /* the hinged walls keep the salt in the box (their pairs' repulsion); on the grid they
     * would own a slanted band of nodes that the shear sweeps across (docs/solver.md 9.5) */
    p.salt_wall_contact = CDEM_SALT_FREE_SLIP;
    salt_cell c;
    const double j0 = 1.0 / (1.0 + confining / p.salt_bulk_modulus);
    if (!salt_cell_open(&c, &p, j0, INFINITY, INFINITY, 0.0, err))
        return 0;
    c.m.gravity = 0.0;
    c.it.loads.gravity = 0.0;
    cdem_loads_set_gravity(&c.it.loads, 0.0, 0.0);
    /* the gap: the packing's mean top (the highest top in columns of a largest diameter), so
     * that the plate touches the salt across the box, not only its highest elements */
    const double col = 2.0 * c.m.max_radius;
    const size_t ncol = (size_t)ceil(c.m.width_m / col);
    double *tops = calloc(ncol, sizeof *tops), sum_top = 0.0;
    for (size_t i = 0; i < c.s.n; i++)
        if (c.s.flags[i] & CDEM_FLAG_SALT) {
            size_t k = (size_t)fmax(0.0, floor(c.s.x[i] / col));
            k = k < ncol ? k : ncol - 1;
            tops[k] = fmax(tops[k], c.s.y[i] + c.s.radius[i]);
        }
    for (size_t k = 0; k < ncol; k++)
        sum_top += tops[k];
    free(tops);
    c.gap = sum_top / (double)ncol - c.y_base;
    const double rw = c.m.radius[0], W = c.m.width_m, H = c.gap;
    /* the plate: wall discs a radius apart (a smooth plate) on the packing, long
     * enough to cover the box while it moves by strain x H */
    const double x_lo = -rw - strain * H - 4.0 * rw, x_hi = W + rw;
    for (double x = x_lo; x <= x_hi; x += rw) /* smooth: the grid alone holds the salt */
        cdem_state_append(&c.s, -1, x, H + rw, rw, c.m.mass[0], 0,
                          cover_plate ? 0u : CDEM_FLAG_WALL | CDEM_FLAG_BASE | CDEM_FLAG_MOVING, 0,
                          NULL, err);
    /* lateral walls above the plate are not needed (and would shear nothing); salt elements
     * reaching above the plate's underside go, so that no salt starts pressed into the plate
     * (an overlap of tens of metres would compress the salt to tens of MPa, and the plate's
     * bumps would then add a pressure-made friction to the viscous stress it measures) */
    unsigned char *keep = malloc(c.s.n);
    for (size_t i = 0; i < c.s.n; i++)
        keep[i] = !((c.s.flags[i] & CDEM_FLAG_WALL) && !(c.s.flags[i] & CDEM_FLAG_BASE) &&
                    c.s.y[i] > H + 2.0 * rw) &&
                  !((c.s.flags[i] & CDEM_FLAG_SALT) && c.s.y[i] + c.s.radius[i] > H) &&
                  !(open_ends && (c.s.flags[i] & CDEM_FLAG_WALL) &&
                    !(c.s.flags[i] & CDEM_FLAG_BASE) && c.s.y[i] > 0.0);
    cdem_state_compact(&c.s, keep, NULL);
    free(keep);
    /* the salt measured again in the box it now fills, and the module set up with it */
    if (cdem_salt_measure(&c.s, W * H, c.sm.reach, &c.layer, err) != CDEM_OK ||
        cdem_salt_configure(&c.salt, &c.m, &c.sm, &c.p, &c.layer, c.it.nb.skin, err) != CDEM_OK) {
        salt_cell_close(&c);
        return 0;
    }
    for (size_t i = 0; i < c.s.n; i++) {
        const int k = couette_wall_kind(&c.s, i, H);
        if (c.s.flags[i] & CDEM_FLAG_SALT)
            c.s.vx[i] = U * (c.s.y[i] - c.y_base) / H;
        else if (k == 1)
            c.s.vx[i] = U;
        else if (k == 2)
            c.s.vx[i] = U * (c.s.y[i] - c.y_base) / H;
    }
    const double dt = c.it.dt;
    const long steps = (long)ceil(strain * H / U / dt);
    const long avg0 = steps / 2;
    double area0 = 0.0, top0, a;
    long n_salt;
    cdem_salt_measures(&c.s, c.layer.phi, &area0, &top0, &n_salt);
    double tau_plate = 0.0, tau_salt = 0.0;
    long n_avg = 0, n_salt_avg = 0;
    enum { BINS = 10 };
    double bin_v[BINS] = {0}, bin_n[BINS] = {0};
    for (long step = 1; step <= steps; step++) {
        for (size_t i = 0; i < c.s.n; i++) { /* the walls' motion of this step */
            const int k = couette_wall_kind(&c.s, i, H);
            if (k == 1) { /* (a cover plate is held at its height too) */
                c.s.vx[i] = U;
                c.s.x[i] += U * dt;
                c.s.vy[i] = 0.0;
                c.s.y[i] = H + rw;
            } else if (k == 2) {
                c.s.vx[i] = U * fmin(fmax((c.s.y[i] - c.y_base) / H, 0.0), 1.0);
                c.s.x[i] += c.s.vx[i] * dt;
            }
        }
        if (cdem_integrator_step(&c.it, &c.s, NULL, 0, 0.0, err) != CDEM_OK) {
            salt_cell_close(&c);
            return 0;
        }
        cdem_salt_measures(&c.s, c.layer.phi, &a, &top0, &n_salt);
        out->area_change = fmax(out->area_change, fabs(a / area0 - 1.0));
        if (step <= avg0)
            continue;
        double fx = 0.0, fb = 0.0, fw = 0.0;
        for (size_t i = 0; i < c.s.n; i++) {
            const int k = couette_wall_kind(&c.s, i, H);
            if (k == 1)
                fx += c.s.fx[i];
            else if (k == 2)
                fw += c.s.fx[i];
            else if (c.s.flags[i] & CDEM_FLAG_BASE)
                fb += c.s.fx[i];
        }
        tau_plate += -fx / W;
        out->tau_base += fb / W;
        out->tau_walls += fw / W;
        n_avg++;
        const cdem_salt *salt = &c.salt;
        for (size_t i = 0; i < c.s.n; i++) {
            if (!(c.s.flags[i] & CDEM_FLAG_SALT))
                continue;
            const double x = c.s.x[i] - U * (c.s.y[i] - c.y_base) / H * (double)step * dt;
            if (x < 0.25 * W || x > 0.75 * W)
                continue; /* the middle half of the box, in its sheared frame */
            const int b = (int)floor((c.s.y[i] - c.y_base) / H * BINS);
            if (b < 0 || b >= BINS)
                continue;
            bin_v[b] += c.s.vx[i];
            bin_n[b] += 1.0;
            if (b >= 2 && b < BINS - 2) { /* the middle 60 % of the gap, as the bulk rate */
                tau_salt += -salt->sxy[i];
                n_salt_avg++;
            }
        }
    }
    /* the bulk rate: the slope of the mean velocity over the middle 60 % of the gap */
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, nn = 0.0;
    for (int b = 2; b < BINS - 2; b++) {
        if (bin_n[b] <= 0.0)
            continue;
        const double yb = (b + 0.5) / BINS * H, vb = bin_v[b] / bin_n[b];
        sx += yb;
        sy += vb;
        sxx += yb * yb;
        sxy += yb * vb;
        nn += 1.0;
    }
    out->eta_set = c.sm.viscosity;
    out->rate_nominal = U / H;
    out->rate_bulk = (nn * sxy - sx * sy) / (nn * sxx - sx * sx);
    out->tau_plate = tau_plate / (double)n_avg;
    out->tau_base /= (double)n_avg;
    out->tau_walls /= (double)n_avg;
    out->tau_salt = n_salt_avg ? tau_salt / (double)n_salt_avg : NAN;
    out->steps = steps;
    out->elements = (long)c.s.n;
    salt_cell_close(&c);
    return 1;
}

/* What a gravity-current run measured: the front x_N(t) (m from the wall's inner face) at
 * every sample, and the fits of x_N = K t^beta over the late window x_N >= window_from x L0. */
typedef struct {
    int n;                  /* samples */
    double t[512], xn[512]; /* s since release, m */
    double area0;           /* m^2, the salt's material area at release (A) */
    double theory_k;        /* 1.411 (rho g A^3 / (3 eta))^(1/5) */
    double beta;            /* fitted exponent over the window */
    double k_ratio;         /* prefactor with the exponent 1/5, over theory_k */
    double t_from, t_to;    /* s, the window */
    double area_change;     /* largest |material area / area0 - 1| */
    long elements;          /* salt elements */
} huppert_result;

/* The fraction of the area of Huppert's similarity profile h ~ (1 - u^2)^(1/3), u = x / x_N,
 * that lies beyond u = s (midpoint sums of 4000 panels: the integrand is bounded). */
static double huppert_tail(double s) {
    enum { N = 4000 };
    double all = 0.0, tail = 0.0;
    for (int k = 0; k < N; k++) {
        const double u = (k + 0.5) / N, w = cbrt(1.0 - u * u) / N;
        all += w;
        if (u > s)
            tail += w;
    }
    return tail / all;
}

/* The salt's front x_N: the x beyond which a fraction `tail` of the salt's material area lies
 * (from the wall's inner face at x = 0), divided by the u at which Huppert's profile leaves
 * that fraction beyond it. An integral measure: a gap between elements inside the current,
 * or one element ahead of it, moves it little, unlike a threshold on a column's thickness. */
static double huppert_front(const cdem_state *s, double phi, double tail) {
    enum { NBIN = 4096 };
    const double bin = 25.0; /* m */
    double a[NBIN] = {0}, total = 0.0;
    for (size_t i = 0; i < s->n; i++) {
        if (!(s->flags[i] & CDEM_FLAG_SALT))
            continue;
        const double ai = s->area_ratio[i] * M_PI * s->radius[i] * s->radius[i] / phi;
        const double xr = s->x[i] + s->radius[i]; /* the element's front edge */
        size_t k = xr > 0.0 ? (size_t)(xr / bin) : 0;
        a[k < NBIN ? k : NBIN - 1] += ai;
        total += ai;
    }
    double beyond = 0.0, lo = 0.0, hi = 1.0;
    size_t k = NBIN;
    while (k > 0 && beyond + a[k - 1] < tail * total)
        beyond += a[--k];
    for (int it = 0; it < 60; it++) { /* u with huppert_tail(u) = tail */
        const double mid = 0.5 * (lo + hi);
        if (huppert_tail(mid) > tail)
            lo = mid;
        else
            hi = mid;
    }
    return (double)k * bin / (0.5 * (lo + hi));
}

/* A block of salt L0 wide and H0 high against the left wall (free slip) on the no-slip base
 * of a box `box_km` long, gravity on, the model's viscosity eta_m; released at t = 0 and run
 * for `runtime` s, the front sampled every `every` s. Fits over x_N >= window_from x L0. */
__attribute__((unused)) static int huppert_run(double box_km, double l0, double h0, int half_radii,
                                               double eta_m, double runtime, double every,
                                               double window_from, huppert_result *out,
                                               cdem_error *err) {
    memset(out, 0, sizeof *out);
    cdem_params p = salt_cell_params(box_km, h0 / 1000.0, half_radii);
    p.salt_wall_contact = CDEM_SALT_FREE_SLIP;
    p.salt_time_scale = p.salt_viscosity / eta_m;
    salt_cell c;
    if (!salt_cell_open(&c, &p, 1.0, l0, INFINITY, 0.0, err))
        return 0;
    const double phi = c.layer.phi, dt = c.it.dt;
    double area0, top, a;
    long n_salt;
    cdem_salt_measures(&c.s, phi, &area0, &top, &n_salt);
    out->area0 = area0;
    out->elements = n_salt;
    const double rho = c.sm.density, g = c.m.gravity, eta = c.sm.viscosity;
    out->theory_k = 1.4112 * pow(rho * g * area0 * area0 * area0 / (3.0 * eta), 0.2);
    const long steps = (long)ceil(runtime / dt), sample = (long)fmax(1.0, round(every / dt));
    for (long step = 1; step <= steps; step++) {
        if (cdem_integrator_step(&c.it, &c.s, NULL, 0, 0.0, err) != CDEM_OK) {
            salt_cell_close(&c);
            return 0;
        }
        if (step % sample != 0)
            continue;
        cdem_salt_measures(&c.s, phi, &a, &top, &n_salt);
        out->area_change = fmax(out->area_change, fabs(a / area0 - 1.0));
        if (out->n < 512) {
            out->t[out->n] = (double)step * dt;
            out->xn[out->n] = huppert_front(&c.s, phi, 0.02);
            out->n++;
        }
    }
    salt_cell_close(&c);
    /* the fits: log x_N = log K + beta log t, and K with beta = 1/5 */
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, nn = 0.0, k5 = 0.0;
    out->t_from = out->t_to = NAN;
    for (int k = 0; k < out->n; k++) {
        if (!(out->xn[k] >= window_from * l0))
            continue;
        const double lx = log(out->t[k]), ly = log(out->xn[k]);
        if (isnan(out->t_from))
            out->t_from = out->t[k];
        out->t_to = out->t[k];
        sx += lx;
        sy += ly;
        sxx += lx * lx;
        sxy += lx * ly;
        k5 += log(out->xn[k] / pow(out->t[k], 0.2));
        nn += 1.0;
    }
    out->beta = nn >= 3.0 ? (nn * sxy - sx * sy) / (nn * sxx - sx * sx) : NAN;
    out->k_ratio = nn >= 1.0 ? exp(k5 / nn) / out->theory_k : NAN;
    return 1;
}

#endif
