/* strain: displacement-gradient fits and finite-strain measures between two element states.
 *
 * For each non-wall element of the current state, the elements within `radius` (default
 * 2 x the largest radius of the reference state) of it in the REFERENCE state, wall elements
 * excluded, itself included, matched by id, give a least-squares fit u = t + G X (X =
 * reference position relative to the element). Fewer than three such elements, or a
 * degenerate (collinear) set, give NaN. Measures are Lagrangian (from C = F^T F, F = I + G);
 * see docs/analysis.md for every formula and the sign conventions (x right, y up; rotation
 * positive clockwise; angles in degrees counter-clockwise from +x).
 * Ownership: callers own every array; cdem_strain_cum owns its sums (_free accepts NULL).
 * Thread safety: pure; the element loop is OpenMP-parallel, schedule(static), every element
 * written by one thread from sums taken in a fixed order: results do not depend on the
 * thread count. Units: gradients and strains dimensionless, rotation in radians. */
#ifndef CDEM_STRAIN_H
#define CDEM_STRAIN_H

#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

/* Number of scalar measures in cdem_strain_measures (for array layouts). */
#define CDEM_STRAIN_NMEASURES 6

/* Finite strain of one element. NaN in every field when undefined. */
typedef struct {
    double e1;        /* maximum extension S1 - 1, >= -1 */
    double e3_neg;    /* shortening -e3 = 1 - S3 (positive when shortened), <= 1 */
    double max_shear; /* maximum shear strain (l1 - l3) / (2 sqrt(l1 l3)), >= 0 */
    double dilation;  /* S1 S3 - 1 (area change), > -1 */
    double rotation;  /* infinitesimal rotation (dUx/dY - dUy/dX) / 2, rad, + clockwise */
    double angle1;    /* direction of S1 in the deformed frame, deg ccw from +x, (-90, 90];
                         NaN when S1 == S3 (no preferred direction) */
} cdem_strain_measures;

/* Closed-form least squares for the m points (X[k], Y[k]) with displacements (ux[k], uy[k]):
 * solves the 3x3 normal equations of u = t + G X for ux and uy (one shared adjugate).
 * g receives {dUx/dX, dUx/dY, dUy/dX, dUy/dY}, t (may be NULL) the translation. Returns 1
 * on success, 0 when m < 3 or the points are (nearly) collinear (g, t set to NaN). */
int cdem_strain_fit(size_t m, const double *X, const double *Y, const double *ux, const double *uy,
                    double g[4], double t[2]);

/* Measures from a displacement gradient g = {dUx/dX, dUx/dY, dUy/dX, dUy/dY}. All NaN when g
 * has a NaN or det F <= 0. */
void cdem_strain_measures_from_gradient(const double g[4], cdem_strain_measures *m);

/* Largest radius over the elements of s (0 when empty). */
double cdem_strain_max_radius(const cdem_state *s);

/* Fits the gradient of every element i of cur (grad[4i..4i+3]) against ref. select (may be
 * NULL = all) limits the fit to elements with select[i] != 0; the others, wall elements and
 * elements absent from ref get NaN. radius <= 0 means 2 x cdem_strain_max_radius(ref). */
cdem_status cdem_strain_gradients(const cdem_state *ref, const cdem_state *cur,
                                  const unsigned char *select, double radius, double *grad,
                                  cdem_error *err);

/* cdem_strain_gradients followed by the measures: out[i] for element i of cur. */
cdem_status cdem_strain_compute(const cdem_state *ref, const cdem_state *cur,
                                const unsigned char *select, double radius,
                                cdem_strain_measures *out, cdem_error *err);

/* Running sums of the scalar measures of successive pairs, indexed by element id: the
 * cumulative strain. angle1 is not summed (kept NaN). */
typedef struct {
    size_t cap;          /* ids 0..cap-1 have a slot */
    double *sum;         /* CDEM_STRAIN_NMEASURES sums per id (layout of the measures) */
    unsigned *count;     /* pairs summed per id */
    int32_t last_number; /* increment number of the last pair added (-1 = none) */
} cdem_strain_cum;

void cdem_strain_cum_init(cdem_strain_cum *c);
void cdem_strain_cum_free(cdem_strain_cum *c);
/* Forgets every sum (keeps the memory). */
void cdem_strain_cum_reset(cdem_strain_cum *c);
/* Adds the measures of one pair (prev -> cur, aligned with cur's elements); NaN fields are
 * skipped. Fails on negative ids. */
cdem_status cdem_strain_cum_add(cdem_strain_cum *c, const cdem_state *cur,
                                const cdem_strain_measures *pair, cdem_error *err);
/* Cumulative measures for the elements of s: the sums of the pairs added; elements with no
 * defined pair get 0 when zero_if_none (the end-of-equilibration increment), else NaN; wall
 * elements NaN. */
void cdem_strain_cum_get(const cdem_strain_cum *c, const cdem_state *s, int zero_if_none,
                         cdem_strain_measures *out);

/* Stress measures from sxx, syy, sxy (compression positive). */
typedef struct {
    double sigma1;    /* largest principal stress, N/m */
    double sigma3;    /* smallest principal stress, N/m */
    double max_shear; /* (sigma1 - sigma3) / 2, N/m, >= 0 */
    double angle1;    /* direction of sigma1, deg ccw from +x, (-90, 90]; NaN if isotropic */
} cdem_stress_principal;

void cdem_stress_principal_from(double sxx, double syy, double sxy, cdem_stress_principal *p);

#endif
