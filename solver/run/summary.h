/* summary: the model summary (the original program's Summary view): a plain-text record of
 * the element count, dimensions, radii and masses, constants, time steps, boundary speed and
 * displacement, increments, faulting mode and geometry, material, heterogeneity and growth
 * strata. Printed by `cdem-run --summary` and stored in every output file.
 * Ownership: the returned text is malloc'd; the caller frees it. Thread safety: pure. */
#ifndef CDEM_SUMMARY_H
#define CDEM_SUMMARY_H

#include "model.h"
#include "params.h"

/* n_free and n_boundary: the free (integrated) elements and the wall, fault and other
 * boundary elements of increment 0, i.e. of the assembly after the boundary mode has added
 * its elements (cdem_run_count_elements); their sum is "the element count" everywhere
 * (docs/format.md, "Counting"). Estimates when elements_estimated is 1 (the text says so). */
cdem_status cdem_summary_text(const cdem_params *p, const cdem_model *m, long n_free,
                              long n_boundary, int elements_estimated, char **text,
                              cdem_error *err);

#endif
