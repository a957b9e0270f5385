/* displacement: see displacement.h. One id map of the reference, one pass over cur. */
#include "displacement.h"

#include <math.h>
#include <stdint.h>

cdem_status cdem_displacement_compute(const cdem_state *ref, const cdem_state *cur,
                                      const unsigned char *select, double *ux, double *uy,
                                      cdem_error *err) {
    cdem_id_map map;
    CDEM_TRY(cdem_id_map_build(&map, ref, err));
    for (size_t i = 0; i < cur->n; i++) {
        if (select && !select[i])
            continue;
        size_t r = cdem_id_map_find(&map, cur->id[i]);
        if (r == SIZE_MAX) {
            ux[i] = uy[i] = NAN;
            continue;
        }
        ux[i] = cur->x[i] - ref->x[r];
        uy[i] = cur->y[i] - ref->y[r];
    }
    cdem_id_map_free(&map);
    return CDEM_OK;
}
