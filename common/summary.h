/* summary: the model summary (the original program's Summary view): a plain-text record of
 * the element count, dimensions, radii and masses, constants, time steps, boundary speed and
 * displacement, increments, faulting mode and geometry, material, heterogeneity and growth
 * strata. Printed by `cdem-run --summary` and stored in every output file.
 * Ownership: the returned text is malloc'd; the caller frees it. Thread safety: pure. */
#ifndef CDEM_SUMMARY_H
#define CDEM_SUMMARY_H

#include "model.h"
#include "params.h"

/* n_elements: the element count of the generated assembly (internal elements), or an
 * estimate when elements_estimated is 1 (the text then says so). */
cdem_status cdem_summary_text(const cdem_params *p, const cdem_model *m, long n_elements,
                              long n_wall_elements, int elements_estimated, char **text,
                              cdem_error *err);

#endif
