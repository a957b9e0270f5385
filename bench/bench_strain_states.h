/* bench_strain_states: the deterministic test states shared by bench_strain.c and strain_numpy.py
 * (the Python script builds the same positions with the same formulas). No RNG: the jitter
 * is a closed-form function of the lattice indices, so both programs see the same packing
 * (to the last few ulps of sin). */
#ifndef CDEM_BENCH_STRAIN_STATES_H
#define CDEM_BENCH_STRAIN_STATES_H

#include "state.h"

#include <math.h>

/* Triangular lattice, spacing 180 m, jitter +-25 m, radii 50..125 m; ncol x nrow elements. */
static void bench_packing(cdem_state *s, int ncol, int nrow) {
    cdem_error err;
    cdem_state_init(s, (size_t)ncol * (size_t)nrow, 0, &err);
    static const double radii[4] = {50.0, 75.0, 100.0, 125.0};
    const double d = 180.0, dy = d * sqrt(3.0) / 2.0;
    for (int r = 0; r < nrow; r++)
        for (int c = 0; c < ncol; c++) {
            double jx = 25.0 * sin(12.9898 * c + 78.233 * r);
            double jy = 25.0 * cos(39.3468 * c + 11.135 * r);
            double x = (c + 0.25 + 0.5 * (r % 2)) * d + jx;
            double y = (r + 0.5) * dy + jy;
            cdem_state_append(s, -1, x, y, radii[(c * 7 + r * 3) % 4], 1.0, 1, 0, 0, NULL, &err);
        }
}

/* Positions after k small increments of a smooth non-homogeneous deformation. */
static void bench_deform(const cdem_state *ref, cdem_state *cur, double k) {
    for (size_t i = 0; i < ref->n; i++) {
        double x = ref->x[i], y = ref->y[i];
        cur->x[i] = x + k * 1e-3 * (0.5 * y + 200.0 * sin(x / 1500.0));
        cur->y[i] = y + k * 1e-3 * (100.0 * cos(y / 900.0) - 0.2 * x);
    }
}

#endif
