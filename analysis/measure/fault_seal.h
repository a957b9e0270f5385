/* fault_seal: throw, heave and layer juxtaposition across one fault zone at one increment
 * (issue 49 items 2 and 3), so that a fault model answers what a fault-seal geologist asks:
 * how far the layers are offset, which layer faces which across the fault, and at what
 * throw a seal layer stops sealing against itself.
 *
 * Method (2-D; free elements with layer >= 1 only: walls, fault ramps and layer-0 elements
 * are ignored):
 *   1. The zone is a straight centre line through (x_top, y_top) and (x_bottom, y_bottom)
 *      (a fault zone of faults.h, or any line) with a half-width. An element's side is the
 *      sign of its horizontal distance d = x - x_line(y) to the line at its own height; it
 *      samples its side when half_width <= |d| <= half_width + band: just outside the zone,
 *      where the horizons are offset but not smeared (Schöpfer et al. 2017 measure throw on
 *      horizons projected from outside the zone in the same way).
 *   2. Horizons: the top of layer L on a side is the highest y + r of the layer's sampled
 *      elements there; the base of the lowest layer is its lowest y - r. The layers are
 *      stacked upward by number (1 at the bottom, growth layers 25.. above), so the base of
 *      layer L is the top of the next lower layer present on that side.
 *   3. The hanging wall is the side whose horizons stand lower (the median of the
 *      left-minus-right offsets decides), so throw is positive for normal and reverse faults
 *      alike. Throw of horizon L = footwall top - hanging-wall top; its height is the mean of
 *      the two tops; heave = throw x |dx/dy| of the line (a vertical zone has none). The total
 *      throw is the median of the horizons' throws.
 *   4. Juxtaposition (Allan 1989, in 2-D: one section through the fault plane): at heights
 *      from the lowest base to the highest top, every `step`, the layer of each side whose
 *      interval (base, top] holds the height; 0 where a side has no layer (above its top,
 *      below its base).
 *   5. Seal layers: for each, the footwall and hanging-wall intervals, the throw across the
 *      layer (mean of its top's and base's throws), their overlap in height, whether it is
 *      still self-juxtaposed (overlap > 0), and the throw at which that is lost: the current
 *      throw plus the overlap (each further metre of throw removes a metre of overlap), which
 *      for a layer of unchanged thickness t is t, the geometric expectation.
 * Not implemented here (issue 49): zones followed through time, throw partitioning between
 * offset and drag, smear and connectivity, the shale gouge ratio.
 * Used by `cdem-strain fault-seal` (analysis/cli/cmd_fault_seal.c).
 * Ownership: the caller owns the state; the result owns its arrays (cdem_fault_seal_free).
 * Thread safety: pure function. Units: m. */
#ifndef CDEM_FAULT_SEAL_H
#define CDEM_FAULT_SEAL_H

#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

typedef struct {
    double x_top, y_top;       /* m, a point of the zone's centre line (its top) */
    double x_bottom, y_bottom; /* m, another (its bottom); y_top != y_bottom */
    double half_width;         /* m, >= 0: elements nearer the line are inside the zone */
    double band;               /* m, > 0: width of the sampling band outside on each side */
} cdem_seal_zone;

typedef struct {
    int layer;           /* the horizon is the top of this layer */
    double footwall_top; /* m */
    double hanging_top;  /* m */
    double height;       /* m, mean of the two tops */
    double throw_m;      /* m, footwall_top - hanging_top */
    double heave;        /* m, throw_m x |dx/dy| of the zone line */
} cdem_seal_horizon;

typedef struct {
    double height; /* m */
    int footwall;  /* layer of the footwall at this height, 0: none */
    int hanging;   /* layer of the hanging wall, 0: none */
} cdem_seal_juxtaposition;

typedef struct {
    int layer;
    double footwall_base, footwall_top; /* m */
    double hanging_base, hanging_top;   /* m */
    double throw_m;                     /* m, across the layer (mean of base and top) */
    double overlap;                     /* m, of the two intervals; <= 0: none */
    int self_juxtaposed;                /* 1: overlap > 0 */
    double loss_throw;                  /* m, throw at which self-juxtaposition is lost */
} cdem_seal_layer;

typedef struct {
    int hanging_wall_right;          /* 1: the hanging wall is on the +x side */
    double mean_radius;              /* m, of the sampled elements */
    double total_throw;              /* m, median of the horizons' throws */
    double total_heave;              /* m, total_throw x |dx/dy| */
    int lowest_layer, highest_layer; /* the layers of the state (free elements) */
    size_t n_horizons;
    cdem_seal_horizon *horizon; /* by layer, bottom up; present on both sides */
    size_t n_rows;
    cdem_seal_juxtaposition *row; /* by height, bottom up */
    size_t n_seals;
    cdem_seal_layer *seal; /* in the order asked */
} cdem_fault_seal_result;

/* Measures throw, heave, juxtaposition and the seal layers (n_seals of them, may be 0) of
 * state s across zone z, sampling heights every `step` m (<= 0: half the mean radius).
 * Fails with CDEM_ERR_INVALID when the state has no layers (every free element has layer 0),
 * the zone is degenerate, a seal layer does not exist in the state ("seal layer 30 does not
 * exist: the layers are 1..24") or is missing on one side of the zone, or fewer than one
 * horizon is found on both sides; CDEM_ERR_NOMEM when memory runs out. On success res owns
 * its arrays. */
cdem_status cdem_fault_seal_measure(const cdem_state *s, const cdem_seal_zone *z,
                                    const int *seal_layers, size_t n_seals, double step,
                                    cdem_fault_seal_result *res, cdem_error *err);

void cdem_fault_seal_free(cdem_fault_seal_result *res);

#endif
