/* displacement: per-element displacement between two element states, matched by id.
 *
 * u = position in cur - position in ref, aligned with cur's elements; NaN for elements that
 * are absent from ref or not selected. The increment rules (incremental = k against k - 5 or
 * the first increment; total = k against the end of equilibration, growth elements against
 * their birth increment) are applied by the analysis context (analysis.h), which calls this
 * with the right pair and selection. Wall elements get their displacement too (walls move).
 * Ownership: the caller owns every array. Thread safety: pure. Units: m. */
#ifndef CDEM_DISPLACEMENT_H
#define CDEM_DISPLACEMENT_H

#include "cdem_error.h"
#include "state.h"

/* ux[i], uy[i] for element i of cur; select (may be NULL = all) limits which elements are
 * computed (the others are left untouched, so several calls can fill one array). */
cdem_status cdem_displacement_compute(const cdem_state *ref, const cdem_state *cur,
                                      const unsigned char *select, double *ux, double *uy,
                                      cdem_error *err);

#endif
