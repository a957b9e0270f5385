/* parallel: the threshold below which the solver's loops stay on one thread.
 *
 * A step of the default model (~2500 elements, ~5000 pairs) takes ~0.1 ms, comparable to
 * the cost of waking a sleeping thread (OMP_WAIT_POLICY=passive) on a shared machine, so
 * small models stay serial; from ~8,000 elements (half radii) the force pass (with the
 * boundary modes' moves, solver/modes/bc.h step_move) and the neighbour-list build are threaded.
 * The integrator and the neighbour list start from CDEM_PAR_MIN and `cdem-run --par-min N`
 * overrides it. Results never depend on it (docs/reliability.md: bit-identical for any
 * thread count). Compile-time constant; no state. */
#ifndef CDEM_PARALLEL_H
#define CDEM_PARALLEL_H

/* Loops over at most this many items run on one thread (elements or pairs). */
#define CDEM_PAR_MIN 8192

/* CDEM_PAR_MIN as a string literal, for help texts. */
#define CDEM_PAR_MIN_STR   CDEM_STRINGIFY(CDEM_PAR_MIN)
#define CDEM_STRINGIFY(x)  CDEM_STRINGIFY_(x)
#define CDEM_STRINGIFY_(x) #x

#endif
