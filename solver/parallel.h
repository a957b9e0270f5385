/* parallel: the thresholds below which the solver's loops stay on one thread.
 *
 * A step of the default model (~2500 elements, ~5000 pairs) takes ~0.1 ms, comparable to
 * the cost of waking a sleeping thread (OMP_WAIT_POLICY=passive) on a shared machine, so
 * small models stay serial; from ~8,000 elements (half radii) the force pass and the
 * neighbour-list build are threaded, the boundary modes' scans from CDEM_PAR_MIN_SCAN. The
 * integrator and the neighbour list start from CDEM_PAR_MIN and `cdem-run --par-min N`
 * overrides it. Results never depend on either (docs/reliability.md: bit-identical for any
 * thread count). Compile-time constants; no state. */
#ifndef CDEM_PARALLEL_H
#define CDEM_PARALLEL_H

/* Loops over fewer items than this run on one thread (elements or pairs). */
#define CDEM_PAR_MIN 8192

/* The boundary modes' loops visit every element to move the few boundary ones (a flag test
 * each, under a nanosecond): below this many elements the scan is shorter than waking a
 * sleeping thread for it (tens of microseconds with the passive wait policy that cdem-run
 * chooses, common/threads.h), so it stays on the calling thread. */
#define CDEM_PAR_MIN_SCAN 65536

/* CDEM_PAR_MIN as a string literal, for help texts. */
#define CDEM_PAR_MIN_STR   CDEM_STRINGIFY(CDEM_PAR_MIN)
#define CDEM_STRINGIFY(x)  CDEM_STRINGIFY_(x)
#define CDEM_STRINGIFY_(x) #x

#endif
