/* law_normal_cohesion: C0 in parallel with the normal force, granular_law = normal-cohesion
 * (the default).
 *   Fs = Ks Xs,   |Fs| <= Fs_max = mu (Fn + C0)   (C0 only while the contact is cohesive)
 * The paper (Cardozo & Hardy 2023, Theory) and the manual describe the shear force as "a
 * threshold-limited elastic spring with a cohesive force term (C0) in parallel with that
 * used to calculate the normal force": the cohesion acts like an extra normal force pressing
 * the two elements together, so it raises the Coulomb threshold by mu C0. At the paper's
 * C0 = 5e9 N and mu = 0.25 that is 1.25e9 N, about 6 times the weight of a smallest default
 * element. A frictionless class (mu = 0: flexural slip, a frictionless weak interval, a
 * smooth base) has no shear strength at all, whatever its C0. Why this law is the default:
 * docs/solver.md, "Which law". Pure, inline. */
#ifndef CDEM_LAW_NORMAL_COHESION_H
#define CDEM_LAW_NORMAL_COHESION_H

#include "law.h"

#include <math.h>

static CDEM_INLINE cdem_shear cdem_law_normal_cohesion(double spring, double fn, double mu,
                                                       double c0) {
    const double limit = mu * (fn + c0);
    cdem_shear s = {spring, spring, 0};
    if (fabs(spring) > limit) {
        s.force = spring > 0.0 ? limit : -limit;
        s.spring = s.force;
        s.slid = 1;
    }
    return s;
}

#endif
