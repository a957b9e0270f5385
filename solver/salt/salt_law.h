/* salt_law: the pair law of the viscous salt (salt.layer; docs/solver.md, "Salt"), between a
 * salt element and any other element. Notation of common/laws/law.h and contact.h:
 * d = x_j - x_i, r = |d|, n = d / r, R = r_i + r_j, dv = v_j - v_i (mid-step velocities),
 * force on i.
 *   normal    F = -Kn (R - r) n while r < R, when one of the two is not salt; none between
 *             two salt elements (their pressure is carried by the salt's grid, salt.h, so
 *             that it adds no frictional strength)
 *   dashpot   F = c w(r) (dv . n) n, w = 1 for r <= R falling linearly to 0 at reach x R: a
 *             weak central dashpot (c = salt.dashpot_fraction x beta x the viscosity, capped
 *             so that it never sets the time step) that damps the element motions the grid
 *             cannot see; central, so a rigid rotation of a pair (dv . n = 0) is not resisted
 *   shear     none: no friction and no cohesion, whatever the classes' materials.
 * The viscous coupling of salt and cover is the grid's, not this law's. It is not a granular
 * law (common/laws/laws.def: a cover's law needs a shear strength, and a pair with a salt
 * element is never in the pair list, cdem_contact_class): only salt.c evaluates it, with
 * cdem_salt_law_pair, so no parameter file can name it. Pure functions; units SI. */
#ifndef CDEM_SALT_LAW_H
#define CDEM_SALT_LAW_H

#include <math.h>

/* The dashpot's weight w(r) at r for R = r_i + r_j and the reach factor (>= 1). */
static inline double cdem_salt_law_weight(double r, double R, double reach) {
    if (r <= R)
        return 1.0;
    const double w = (reach * R - r) / ((reach - 1.0) * R);
    return w > 0.0 ? w : 0.0;
}

/* The force on i of a salt pair (at least one of i, j salt; both_salt: both are): d = (dx, dy),
 * 0 < r2 = |d|^2 < (reach R)^2, dv = (dvx, dvy); kn the repulsion (N/m), c the dashpot
 * (N s/m), c_contact an extra normal dashpot while the pair touches (physics.damping_mode =
 * contact: the cover's contact dashpot; 0 otherwise). */
static inline void cdem_salt_law_pair(double dx, double dy, double r2, double R, double dvx,
                                      double dvy, int both_salt, double kn, double c,
                                      double c_contact, double reach, double *fx, double *fy) {
    const double r = sqrt(r2);
    const double nx = dx / r, ny = dy / r;
    const double vn = dvx * nx + dvy * ny;
    double f = c * cdem_salt_law_weight(r, R, reach) * vn; /* along n, on i */
    if (r < R && !both_salt)
        f += c_contact * vn - kn * (R - r);
    *fx = f * nx;
    *fy = f * ny;
}

#endif
