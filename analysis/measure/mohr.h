/* mohr: Mohr-Coulomb failure envelope from biaxial tests at several confining pressures.
 *
 * Each test gives the confining pressure sigma3 and the peak differential stress
 * q = sigma1 - sigma3 (N/m, compression positive). The envelope tau = C + sigma tan(phi)
 * tangent to all Mohr circles makes the peak stresses lie on the line
 *   sigma1 = 2 C tan(45 + phi/2) + sigma3 tan^2(45 + phi/2) = a + b sigma3,
 * fitted by least squares (gsl_fit_linear, with its covariance). Then
 *   phi = asin((b - 1)/(b + 1)),  C = a / (2 sqrt(b)),
 * and the standard errors follow by linear error propagation (docs/rendering.md,
 * "Mohr-Coulomb fit"). With exactly 2 tests the line is exact and the errors are NaN.
 * The tests come from biaxial run files (cdem_mohr_read_runs: sigma3 is the run's
 * boundary.confining_pressure, q the largest differential stress of its time series; the
 * series are kept for the stress-strain curves of the pictures) or from a text table.
 * Ownership: caller owns arrays; cdem_mohr_runs owns its arrays (cdem_mohr_runs_free).
 * Thread safety: pure functions but for the readers (one file each, nothing shared).
 * Units: stresses N/m (the 2-D model's force per unit length), phi in radians. */
#ifndef CDEM_MOHR_H
#define CDEM_MOHR_H

#include "cdem_error.h"

#include <stddef.h>

typedef struct {
    double a, b;           /* sigma1 = a + b sigma3: intercept (N/m) and slope (>= 1) */
    double cov_aa, cov_ab; /* covariance of a (N^2/m^2) and of a with b (N/m) */
    double cov_bb;         /* variance of b */
    double cohesion;       /* C, N/m */
    double cohesion_err;   /* standard error of C, N/m; NaN when n = 2 */
    double friction;       /* phi, radians, 0 <= phi < pi/2 */
    double friction_err;   /* standard error of phi, radians; NaN when n = 2 */
    double residual_ss;    /* sum of squared residuals of sigma1, N^2/m^2 */
    size_t n;              /* number of tests used, >= 2 */
} cdem_mohr_fit;

/* Fits the envelope to n >= 2 tests. Fails (naming the test and value) on non-finite or
 * negative sigma3, non-positive q, all sigma3 equal, or a fitted slope b < 1 (negative
 * friction angle). */
cdem_status cdem_mohr_fit_envelope(const double *sigma3, const double *q, size_t n,
                                   cdem_mohr_fit *fit, cdem_error *err);

/* The biaxial tests of n run files (cdem_mohr_read_runs). */
typedef struct {
    size_t n;           /* runs */
    double *sigma3, *q; /* per run: confining pressure and peak differential stress, N/m */
    double **strain;    /* per run: axial strain of each time-series sample */
    double **stress;    /* per run: differential stress of each sample, MPa */
    size_t *n_samples;  /* per run: time-series samples */
} cdem_mohr_runs;

/* Reads the runs files[0..n): each must be a biaxial run (boundary.mode = biaxial) with
 * time-series samples; fails naming the file otherwise (or when it cannot be read). q is
 * the largest finite differential stress of the series (-inf when none is finite: the fit
 * refuses it). out is freed by cdem_mohr_runs_free, also after a failure. */
cdem_status cdem_mohr_read_runs(const char *const *files, size_t n, cdem_mohr_runs *out,
                                cdem_error *err);
void cdem_mohr_runs_free(cdem_mohr_runs *r);

/* Reads a text table of tests: two whitespace-separated columns sigma3 q (N/m) per line,
 * '#' comments and blank lines ignored. *sigma3 and *q are malloc'd (caller frees). */
cdem_status cdem_mohr_read_table(const char *path, double **sigma3, double **q, size_t *n,
                                 cdem_error *err);

#endif
