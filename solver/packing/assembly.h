/* assembly: generates the initial assembly: fixed wall elements (base, left and right walls)
 * and a dense, random, polydisperse packing of circular elements between them.
 *
 * Method: sequential gravity deposition (Visscher-Bolsterli): each disc is dropped at a
 * random x, falls, and rolls over the discs it meets into the first stable pocket (two discs,
 * a disc and a wall, or the base). It is purely geometric, O(N) with a cell grid, and leaves
 * no overlap; the solver's equilibration settles the assembly dynamically. Radius classes
 * are drawn in number fractions 4:3:2:1 (smallest to largest); a disc is kept when its
 * lowest point rests at or below the assembly height. docs/assembly.md gives the reasons.
 * Frame: origin at the bottom-left inner corner, x right, y up; inner wall surfaces at
 * x = 0, x = width, y = 0. Units: m, kg per metre of thickness.
 * Determinism: a gsl_rng_mt19937 seeded with p->seed; same parameters -> same state, bit for
 * bit. Ownership: the caller owns the state; the builder keeps no memory after returning.
 * Thread safety: reentrant (all scratch lives in the call). */
#ifndef CDEM_ASSEMBLY_H
#define CDEM_ASSEMBLY_H

#include "cdem_error.h"
#include "model.h"
#include "params.h"
#include "state.h"

typedef struct {
    long n_internal;       /* internal (free) elements generated, >= 0 */
    long n_wall;           /* wall elements (base + left + right), >= 0 */
    double top_mean;       /* m, mean of the top-surface profile (max y + r per column of
                              width 2 x max radius), about height + one radius */
    double top_max;        /* m, highest point of any internal disc (max of y + r) */
    double area_fraction;  /* sum of internal disc areas / (width x height), 0..~0.9 */
    double wall_radius;    /* m, radius of every wall element (smallest element radius) */
    double wall_spacing;   /* m, centre spacing of the lateral walls' elements (= wall_radius) */
    double base_spacing;   /* m, centre spacing of the base's elements (assembly.base_spacing) */
    long n_guard_discards; /* drops discarded by a numerical guard (a disc wedged without
                              support, a final overlap, too many moves); 0 in practice */
} cdem_assembly_info;

/* Builds the assembly into s, which must be initialised (cdem_state_init) and empty.
 * Geometry from p (width, height, unit_scaling, wall_height_multiplier, seed), radii and
 * masses from m (radius[], mass[]). Appends the internal elements first (ids 0..n-1, layer
 * 0, flags 0, born 0, sorted row-major by cells of 2 x max radius, bottom row first), then
 * the wall elements (flag CDEM_FLAG_WALL, the base also CDEM_FLAG_BASE; layer 0): the base from
 * left to right, then the left wall and the right wall from bottom to top. info may be NULL (zeroed
 * on failure). Fails with CDEM_ERR_INVALID (non-empty state, NULL arguments), CDEM_ERR_RANGE (sizes
 * or radii not finite and positive, radii not ascending, an assembly too small for the largest disc
 * or too large for the packing's 32-bit indices: cdem_assembly_check) or CDEM_ERR_NOMEM; s is then
 * left empty. */
cdem_status cdem_assembly_build(const cdem_params *p, const cdem_model *m, cdem_state *s,
                                cdem_assembly_info *info, cdem_error *err);

/* The checks cdem_assembly_build makes of p and m before it builds anything (sizes, radii,
 * masses, and the packing's 32-bit indices: an assembly whose densest packing of its smallest
 * discs would number more than 2^31 - 1 discs or grid cells is refused, CDEM_ERR_RANGE);
 * builds nothing. The memory the model needs is cdem_run_check_memory's (solver/run/run.h). */
cdem_status cdem_assembly_check(const cdem_params *p, const cdem_model *m, cdem_error *err);

/* Counts the internal and wall elements the parameters generate (builds the assembly into a
 * scratch state and frees it). Either output may be NULL. */
cdem_status cdem_assembly_count(const cdem_params *p, const cdem_model *m, long *n_internal,
                                long *n_wall, cdem_error *err);

#endif
