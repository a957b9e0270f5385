/* estimate: see estimate.h. */
#include "estimate.h"

#include <math.h>

double cdem_estimate_wall_seconds(double n, double steps, double increments) {
    if (!(n > 0.0))
        return 0.0;
    return n * (steps * CDEM_ESTIMATE_NS_PER_ELEMENT_STEP * 1e-9 +
                increments * CDEM_ESTIMATE_US_PER_ELEMENT_INCREMENT * 1e-6);
}

double cdem_estimate_height_diameters(const cdem_model *m) {
    return m && m->average_radius > 0.0 ? m->height_m / (2.0 * m->average_radius) : 0.0;
}

double cdem_estimate_equilibration_needed(const cdem_model *m) {
    if (!m || !(m->gravity > 0.0) || !(m->kn > 0.0) || !(m->damping > 0.0))
        return 0.0;
    const double n = cdem_estimate_height_diameters(m), tau = m->damping / m->kn;
    return 100.0 *
           ceil((CDEM_ESTIMATE_SETTLE_FIXED_S + CDEM_ESTIMATE_SETTLE_PER_TAU * tau * n * n) /
                100.0);
}
