/* voids: open space that a granular rock mass should not hold, in one increment.
 *
 * Two measures, each of the free (non-boundary) elements:
 *   - the steepest surface slope: the surface's envelope at x is the highest element top
 *     among the free elements whose centres lie in a column of about 2 x the largest free
 *     radius centred at x (common/surface.h), the column slid along the model in steps of
 *     about an eighth of that radius and kept inside the free elements' extent; the
 *     surface's height at x is the envelope's mean over that column (the steps where a
 *     single high element enters or leaves the column smoothed). The slope between two
 *     heights exactly `window` metres apart is atan(|height difference| / window), and the
 *     steepest of these is reported. A graben flank or a repose slope gives a few tens of
 *     degrees; a standing cliff, or the wall of a chasm with rubble on its floor, 60-80
 *     degrees over a kilometre. Where a stretch of about 2 x that radius holds no free
 *     element (a bare floor), no height is defined near it and no slope is taken there;
 *     when the extent is shorter than the window and about four radii, none is (0 degrees,
 *     x0 = x1 = 0).
 *   - voids: the elements are rasterised (cells of a quarter of the smallest free radius;
 *     wall, fault and other boundary elements count as solid). The clearance of an empty cell
 *     is its distance to the nearest solid cell (a chamfer distance transform, within 8 % of
 *     the Euclidean one): the largest disc centred there that touches nothing. The outside is
 *     what a disc of the largest free radius r_max reaches from the sky through cells of
 *     clearance >= r_max. A void is a region of the rest where such a disc fits (cells of
 *     clearance >= r_max), whose room for the disc's centre covers at least a disc of
 *     r_max / 4 (a cavity of 1.25 r_max or more), and which lies in the rock mass (most of
 *     its cells are nearest to a free element, not to a wall or a fault ramp): room for the
 *     largest element that gravity should have filled (a cavity under a cohesive arch, a
 *     crack between separating blocks). The pores of a packing have far less clearance.
 *   - open fissures: in every cell column of the raster, the depth of its first solid cell
 *     (from the sky down) below the rim, the lower of the highest free-element cells within
 *     2 r_max on either side; the deepest is reported. A crack or slot open to the sky but
 *     narrower than 4 r_max (a gap between separating blocks) is as deep as it is open; a
 *     slope or a step gives its drop over 2 r_max, the notches between surface elements
 *     about an element.
 * Used by `cdem-strain voids` and by the material regression tests (tests/test_material.c).
 * Ownership: the caller owns the state. Thread safety: pure function; scratch memory is
 * allocated per call. Units: m, m^2, degrees. */
#ifndef CDEM_VOIDS_H
#define CDEM_VOIDS_H

#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

typedef struct {
    double window;       /* m, horizontal span of the slope measure, > 0 */
    double column_width; /* m, the sliding column's width: ~2 x the largest free radius */
    double steepest_deg; /* degrees, 0..90: steepest slope over `window` */
    double steepest_x0, steepest_x1; /* m, that slope's ends (the columns' centres) */
    double cell;                     /* m, raster cell size */
    double min_clearance;            /* m, clearance that makes a void: largest free radius */
    double void_min_room;            /* m^2, the smallest room that counts (pi r_max^2 / 16) */
    size_t n_voids;                  /* voids found */
    double void_area;                /* m^2, their room (area of clearance >= min_clearance) */
    double largest_clearance;        /* m, largest clearance inside the rock mass (not outside,
                                        nearest solid a free element, in the free elements' box) */
    double largest_x, largest_y;     /* m, where it is */
    double fissure_width;            /* m, the rim search on either side, 2 r_max */
    double fissure_depth;            /* m, the deepest open fissure (0: none) */
    double fissure_x, fissure_y;     /* m, its column and bottom */
} cdem_voids_result;

/* Measures state s with slope window `window` (m, at least the largest free element's
 * diameter). Fails with CDEM_ERR_INVALID when s has no free element or window is not a
 * number of at least that diameter, CDEM_ERR_NOMEM when the raster
 * cannot be allocated. */
cdem_status cdem_voids_measure(const cdem_state *s, double window, cdem_voids_result *res,
                               cdem_error *err);

#endif
