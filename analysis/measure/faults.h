/* faults: fault zones picked from a per-element strain field, so that a figure's faults can be
 * counted and measured (dip, dip direction, where they reach the surface) instead of
 * described.
 *
 * Method (free elements only; boundary elements and NaN values are ignored, and salt elements
 * unless include_salt: a viscous salt's strain is flow, spread through the layer, not a
 * fault's, and it raised the field's outlier bound of a salt model above its cover's faults):
 *   1. Bin the values on a grid of square cells of side `bin` (default 2 x the largest free
 *      radius: about one element across) and smooth each row along x with weights 1-2-1.
 *   2. In every row, each maximal run of cells at or above `threshold` is one pick, placed at
 *      the value-weighted centre of the run. The default threshold is the field's own outlier
 *      bound, median + 3 x 1.4826 x MAD of the cells' values (a robust 3 sigma): a fault zone
 *      is where the strain stands out from the rest, whatever the displacement, and a weak
 *      antithetic fault (0.64 in the default model's graben) counts as well as a strong
 *      synthetic one (8). A fixed value (the default until 2026-11, 1) missed the former.
 *   3. Picks are linked from the top row down into zones: a pick continues the zone whose
 *      last pick is in one of the two rows above and nearest in x, within `max_shift` x the
 *      row spacing (nearest pairs first, one pick per zone per row). A shift of up to 3 cells
 *      per cell of depth keeps faults dipping 18 degrees or more.
 *   4. A zone that spans at least `min_rows` rows is a fault zone; a least-squares line
 *      x = a + c y through its picks (weighted by their value sums) gives its dip,
 *      atan(1 / |c|), and its dip direction: toward -x ("left") when x grows upward (c > 0),
 *      toward +x ("right") when it shrinks.
 * Conjugate zones that cross merge into one run in the rows where they touch; the linking
 * keeps the two branches apart above and below, so an X gives up to four short zones or two
 * long ones. A thrust verges toward the side opposite to its dip direction.
 * Used by `cdem-strain faults` and by the examples' comparison tables.
 * Ownership: the caller owns the state and values; the result owns its zones
 * (cdem_faults_free). Thread safety: pure function. Units: m, degrees. */
#ifndef CDEM_FAULTS_H
#define CDEM_FAULTS_H

#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

typedef struct {
    double threshold; /* value at or above which a cell belongs to a zone, > 0; 0: the
                         field's outlier bound (median + 3 robust standard deviations) */
    double bin;       /* m, cell size; <= 0: 2 x the largest free radius */
    int min_rows;     /* rows a zone must span to count, >= 2 (default 4) */
    double max_shift; /* largest x shift between linked picks, in cells per row (default 3) */
    int include_salt; /* 1: salt elements count too (default 0: the cover's faults only) */
} cdem_faults_options;

typedef struct {
    double x_top, y_top;       /* m, the zone's highest pick */
    double x_bottom, y_bottom; /* m, its lowest pick */
    double dip_deg;            /* degrees, 0 (flat) .. 90 (vertical) */
    int dips_right;            /* 1: dips toward +x; 0: toward -x */
    int rows;                  /* rows spanned (top to bottom) */
    double mean_value;         /* mean of the smoothed values of its picks' cells */
    double max_value;          /* the largest smoothed cell value in it */
} cdem_fault_zone;

typedef struct {
    double bin;            /* m, the cell size used */
    double threshold;      /* the threshold used (the bound found, for threshold 0) */
    size_t n;              /* zones found */
    cdem_fault_zone *zone; /* n zones, ordered by x_top */
} cdem_faults_result;

/* Default options: threshold 0 (the field's outlier bound), bin 0 (2 x the largest free
 * radius), min_rows 4, max_shift 3. */
void cdem_faults_default_options(cdem_faults_options *o);

/* Picks the fault zones of state s from values v (one per element, NaN where undefined).
 * Fails with CDEM_ERR_INVALID when the options are out of range (threshold < 0) or s has no free
 * element with a value, CDEM_ERR_NOMEM when memory runs out. On success res owns its zones. */
cdem_status cdem_faults_pick(const cdem_state *s, const double *v, const cdem_faults_options *o,
                             cdem_faults_result *res, cdem_error *err);

void cdem_faults_free(cdem_faults_result *res);

#endif
