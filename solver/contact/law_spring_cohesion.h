/* law_spring_cohesion: the manual's Equation 2 as printed, granular_law = spring-cohesion.
 *   Fs = Ks Xs + C0 sgn(Xs),   |Fs| <= Fs_max = mu Fn   (C0 only while cohesive)
 * The cohesion is added to the elastic shear force in the sense of the tangential
 * displacement, and the Coulomb cap mu Fn has no cohesive part: a cohesive contact pushes
 * its pair apart tangentially with C0 as soon as it is sheared at all, and is at its limit
 * whenever C0 > mu Fn. With the paper's values the whole assembly flows (docs/solver.md,
 * "Which law"); kept so that the printed equation can be run and compared. At the limit the
 * spring is set so that Ks Xs alone equals the limit force (the spring stores the force,
 * cohesion excluded). Pure, inline. */
#ifndef CDEM_LAW_SPRING_COHESION_H
#define CDEM_LAW_SPRING_COHESION_H

#include "law.h"

#include <math.h>

static CDEM_INLINE cdem_shear cdem_law_spring_cohesion(double spring, double fn, double mu,
                                                       double c0) {
    const double limit = mu * fn;
    double f = spring;
    if (c0 > 0.0 && spring != 0.0)
        f += spring > 0.0 ? c0 : -c0;
    cdem_shear s = {f, spring, 0};
    if (fabs(f) > limit) {
        s.force = f > 0.0 ? limit : -limit;
        s.spring = s.force;
        s.slid = 1;
    }
    return s;
}

#endif
