/* stress: per-element Love-Weber stress from the contact forces of the last step.
 *   sigma_ab(i) = -(1 / A_i) sum_{contacts c of i} b_a f_b,  A_i = pi r_i^2,
 * with b the branch vector from the centre of i to the contact point and f the contact
 * force on i; symmetrised (sxy = the mean of the two off-diagonal terms). The minus sign
 * makes compression positive (a compressive contact pushes i away from the contact point).
 * The contact point lies on the line of centres at r_i - delta/2 from i's centre, delta =
 * R - r the overlap (negative for a stretched bond), so both branch vectors add up to r.
 * Wall and fault elements get a stress too (from their contacts).
 * Units: N/m (force per metre of thickness over an area in m^2 per metre), compression
 * positive. Thread safety: writes only s->sxx/syy/sxy; deterministic for any thread count
 * (per-element sums over the CSR in fixed order). */
#ifndef CDEM_STRESS_H
#define CDEM_STRESS_H

#include "cdem_error.h"
#include "neighbour.h"
#include "state.h"

/* Fills s->sxx, s->syy, s->sxy (enabling the stress arrays if needed) from the pair list
 * and its force slots (the forces of the last evaluation at the current positions). */
cdem_status cdem_stress_compute(const cdem_neighbour *nb, cdem_state *s, cdem_error *err);

#endif
