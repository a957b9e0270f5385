/* analysis_fixtures: helpers shared by the analysis tests (header-only, static functions).
 * make_packing builds a random disc packing with the model's four radii (seeded RNG, no
 * overlap, rejection sampling on a cell grid of candidate positions) plus a row of base
 * wall elements; deform_affine applies x' = x0 + F (x - x0) to every free element. */
#ifndef CDEM_ANALYSIS_FIXTURES_H
#define CDEM_ANALYSIS_FIXTURES_H

#include "state.h"

#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdlib.h>

/* A random assembly of about n_target discs in [0, w] x [0, h] (m): a triangular lattice of
 * spacing 180 m with every centre jittered by up to +-25 m and radii drawn from the model's
 * four radii (50..125 m), seeded; plus a row of base wall elements (radius 50 m) at
 * y = -50 m. Dense like a settled assembly: every element has its lattice neighbours within
 * the strain search radius 2 x 125 m. Elements beyond n_target are not added. */
__attribute__((unused)) static void make_packing(cdem_state *s, size_t n_target, double w, double h,
                                                 unsigned long seed) {
    cdem_error err;
    cdem_state_init(s, n_target + 64, 0, &err);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    static const double radii[4] = {50.0, 75.0, 100.0, 125.0};
    const double d = 180.0, dy = d * sqrt(3.0) / 2.0;
    for (int row = 0; (row + 0.5) * dy < h && s->n < n_target; row++)
        for (int col = 0; (col + 0.75) * d < w && s->n < n_target; col++) {
            double x = (col + 0.25 + 0.5 * (row % 2)) * d + 50.0 * (gsl_rng_uniform(rng) - 0.5);
            double y = (row + 0.5) * dy + 50.0 * (gsl_rng_uniform(rng) - 0.5);
            double r = radii[gsl_rng_uniform_int(rng, 4)];
            cdem_state_append(s, -1, x, y, r, 1.0, 1 + (int)(y / h * 24), 0, 0, NULL, &err);
        }
    for (double x = 50.0; x < w; x += 100.0)
        cdem_state_append(s, -1, x, -50.0, 50.0, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err);
    gsl_rng_free(rng);
}

/* Applies x' = (x0, y0) + F (x - (x0, y0)) to every non-wall element of s. */
__attribute__((unused)) static void deform_affine(cdem_state *s, const double F[4], double x0,
                                                  double y0) {
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        double X = s->x[i] - x0, Y = s->y[i] - y0;
        s->x[i] = x0 + F[0] * X + F[1] * Y;
        s->y[i] = y0 + F[2] * X + F[3] * Y;
    }
}

#endif
