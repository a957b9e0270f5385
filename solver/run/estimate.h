/* estimate: what a run will cost and whether its equilibration is long enough, known before
 * it runs (cdem-run --summary, and the summary stored in every run file). Every figure comes
 * from the model and from constants measured once and kept here (docs/performance.md,
 * "Estimates before a run"): nothing reads the clock or the machine, so the summary that
 * prints them stays reproducible. The wall time is that of the CPU the constants were
 * measured on, and is labelled so. Thread safety: pure. Units: SI. */
#ifndef CDEM_ESTIMATE_H
#define CDEM_ESTIMATE_H

#include "model.h"

/* One element-step of a run on one thread of the benchmark machine (ns), and the CPU it is
 * (docs/performance.md, "Scale": 13.1-15.0 ns per element-step at 10^4-10^6 elements,
 * AMD EPYC Zen 5, idle, 1 thread; cdem-run's own rate on the same machine, "Estimates before
 * a run"). */
#define CDEM_ESTIMATE_NS_PER_ELEMENT_STEP 15.0
#define CDEM_ESTIMATE_CPU                 "an AMD EPYC (Zen 5)"
/* Two threads take this fraction of one thread's time (the same table: 7.1-9.3 ns against
 * 13.1-15.0). */
#define CDEM_ESTIMATE_TWO_THREADS 0.6
/* Writing an increment (µs per element; the same table: 0.43-1.13). */
#define CDEM_ESTIMATE_US_PER_ELEMENT_INCREMENT 1.0

/* The equilibration rule of thumb (docs/performance.md, "Estimates before a run"): a pile
 * settles like an overdamped column, in a time proportional to damping / Kn times the square
 * of its height in average diameters, plus the first fall: needed = A + B (c / Kn) N^2 (c the
 * damping, N the height in average diameters), calibrated on five bench/bench_settling runs
 * 29-128 diameters tall (they came to rest after 185-2493 s; least squares 88 + 2.70 x,
 * rounded up here so that every run lies under the rule). */
#define CDEM_ESTIMATE_SETTLE_FIXED_S 100.0
#define CDEM_ESTIMATE_SETTLE_PER_TAU 3.0

/* Wall time of a run (s) of n elements over steps time steps writing increments increments,
 * on CDEM_ESTIMATE_CPU. */
double cdem_estimate_wall_seconds(double n, double steps, double increments);

/* The assembly's height in average element diameters (m->height_m / (2 r_avg)). */
double cdem_estimate_height_diameters(const cdem_model *m);

/* The equilibration the assembly needs to come to rest under gravity (s; the rule above,
 * rounded up to a whole 100 s), 0 when the model has no gravity (nothing settles). */
double cdem_estimate_equilibration_needed(const cdem_model *m);

#endif
