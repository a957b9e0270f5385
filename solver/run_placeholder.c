/* run_placeholder: TEMPORARY stand-ins for cdem_run and cdem_run_count_elements (run.h) so
 * that the params branch links cdem-run before the solver branch is merged. The coordinator
 * deletes this file at merge; nothing here simulates anything.
 * cdem_run fails with CDEM_ERR_UNSUPPORTED; cdem_run_count_elements returns the packing
 * estimate of cdem_model_estimate_elements and a rough wall count (base plus two lateral
 * walls lined with the smallest elements). */
#include "run.h"

#include "model.h"

#include <math.h>

cdem_status cdem_run(const cdem_params *p, const cdem_run_options *opt, cdem_error *err) {
    (void)p;
    (void)opt;
    return CDEM_FAIL(err, CDEM_ERR_UNSUPPORTED, "the solver is not part of this build yet");
}

cdem_status cdem_run_count_elements(const cdem_params *p, long *n_internal, long *n_wall,
                                    cdem_error *err) {
    if (!p || !n_internal || !n_wall)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_run_count_elements: NULL argument");
    *n_internal = cdem_model_estimate_elements(p);
    /* wall length in units / diameter of the smallest element (0.1 or 0.05 units) */
    double diameter = p->half_radii ? 0.05 : 0.1;
    double length = p->width + 2.0 * p->height * p->wall_height_multiplier;
    *n_wall = lround(length / diameter);
    return CDEM_OK;
}
