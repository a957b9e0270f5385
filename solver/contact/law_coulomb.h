/* law_coulomb: the Mohr-Coulomb granular contact, granular_law = coulomb.
 *   Fs = Ks Xs,   |Fs| <= Fs_max = mu Fn + C0   (C0 only while the contact is cohesive)
 * The cohesion adds to the strength, not to the spring force: an unloaded cohesive contact
 * carries no shear force, and at Fn = 0 it still resists C0 of shear. This was cdem-c's only
 * law before version 0.2 (cdem-c's first reading of the manual). With the paper's C0 = 5e9 N a
 * contact then holds about 25 times the weight of a smallest element at zero normal force,
 * so 5 km cliffs stand (docs/solver.md, "Which law"). Kept for users who want a
 * Mohr-Coulomb contact. Part of the shared kernel in contact.h: one inline function, pure. */
#ifndef CDEM_LAW_COULOMB_H
#define CDEM_LAW_COULOMB_H

#include "law.h"

#include <math.h>

static CDEM_INLINE cdem_shear cdem_law_coulomb(double spring, double fn, double mu, double c0) {
    double limit = mu * fn;
    if (c0 > 0.0)
        limit += c0;
    cdem_shear s = {spring, spring, 0};
    if (fabs(spring) > limit) {
        s.force = spring > 0.0 ? limit : -limit;
        s.spring = s.force;
        s.slid = 1;
    }
    return s;
}

#endif
