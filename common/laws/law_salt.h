/* law_salt: the pair law of the viscous salt (salt.layer; docs/solver.md, "Salt"), between a
 * salt element and any other element. Notation of law.h and contact.h: d = x_j - x_i,
 * r = |d|, n = d / r, R = r_i + r_j, dv = v_j - v_i (mid-step velocities), force on i.
 *   normal    F = -Kn (R - r) n while r < R, when one of the two is not salt; none between
 *             two salt elements (their pressure is carried by the salt's grid,
 *             solver/step/salt.h, so that it adds no frictional strength)
 *   dashpot   F = c w(r) (dv . n) n, w = 1 for r <= R falling linearly to 0 at reach x R: a
 *             weak central dashpot (c = salt.dashpot_fraction x beta x the viscosity, capped
 *             so that it never sets the time step) that damps the element motions the grid
 *             cannot see; central, so a rigid rotation of a pair (dv . n = 0) is not resisted
 *   shear     none: no friction and no cohesion, whatever the classes' materials (the
 *             scalar kernel below: a spring that never holds)
 * The viscous coupling of salt and cover is the grid's, not this law's. A pair with a salt
 * element is never in the pair list (cdem_contact_class): solver/step/salt.c evaluates it with
 * cdem_law_salt_pair. As a model's material.granular_law the parameter check refuses it (a
 * cover needs a shear strength). The file's three parts: law.h; no AVX2 kernel (the vector
 * path evaluates it with the scalar one). */
#if defined(CDEM_LAW_SCALAR) && !defined(CDEM_LAW_SALT_SCALAR)
#define CDEM_LAW_SALT_SCALAR

#include "law.h"

/* No shear strength: the trial force is never transmitted and no spring is kept. */
static CDEM_INLINE cdem_shear cdem_law_salt(double spring, double fn, double mu, double c0) {
    (void)fn;
    (void)mu;
    (void)c0;
    return cdem_law_cap(spring, spring, 0.0);
}

/* The dashpot's weight w(r) at r for R = r_i + r_j and the reach factor (>= 1). */
static CDEM_INLINE double cdem_law_salt_weight(double r, double R, double reach) {
    if (r <= R)
        return 1.0;
    const double w = (reach * R - r) / ((reach - 1.0) * R);
    return w > 0.0 ? w : 0.0;
}

/* The force on i of a salt pair (at least one of i, j salt; both_salt: both are): d = (dx, dy),
 * 0 < r2 = |d|^2 < (reach R)^2, dv = (dvx, dvy); kn the repulsion (N/m), c the dashpot
 * (N s/m), c_contact an extra normal dashpot while the pair touches (physics.damping_mode =
 * contact: the cover's contact dashpot; 0 otherwise). */
static CDEM_INLINE void cdem_law_salt_pair(double dx, double dy, double r2, double R, double dvx,
                                           double dvy, int both_salt, double kn, double c,
                                           double c_contact, double reach, double *fx, double *fy) {
    const double r = sqrt(r2);
    const double nx = dx / r, ny = dy / r;
    const double vn = dvx * nx + dvy * ny;
    double f = c * cdem_law_salt_weight(r, R, reach) * vn; /* along n, on i */
    if (r < R && !both_salt)
        f += c_contact * vn - kn * (R - r);
    *fx = f * nx;
    *fy = f * ny;
}

#endif

#ifdef CDEM_LAW
CDEM_LAW(SALT, "salt",
         "no shear strength: the pair law of salt elements (repulsion, a weak normal dashpot, no "
         "friction, no cohesion; salt.layer), not a cover's",
         cdem_law_salt, NULL)
#endif
