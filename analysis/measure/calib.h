/* calib: the search of automatic inverse calibration (cdem-strain calibrate), with no I/O:
 * given what has been measured so far, it says which element properties to test next, or
 * that the search is over and why.
 *
 * The problem is a set of pairs, each an input the search may change (the element friction
 * mu, the cohesion C0) and the bulk property it mainly sets (the friction angle phi, the
 * cohesion C), with a target, a tolerance and the input's bounds. Every map input -> output
 * is taken as increasing over the bounds (the premise: mu -> phi and C0 -> C are
 * monotone over the useful range); the search exploits it instead of fitting a model of the
 * whole map. But the maps are coupled: in the biaxial test C rises with mu as much as with C0
 * (at 1000 m the damping makes C, and more of it the higher the friction), so a cohesion is
 * reachable at one friction angle and out of reach at another. Hence:
 *   - each pair is searched as a one-dimensional root, on the best point and the points
 *     where the other outputs are within 2 tolerances of their targets (the other inputs
 *     about where they must end), or on all points while these share one input; points of
 *     the same input are replicates, their outputs averaged (one lucky packing must not hold
 *     an input where the others say it is wrong);
 *   - a pair whose target is bracketed (a point below, a point above) takes the secant
 *     through the two points nearest the target when it falls in the bracket's inner 80 %,
 *     else false position kept there (so a far end, such as a bound, cannot make it creep);
 *   - a pair whose points all lie on one side extrapolates by the secant of the nearest
 *     point and the next (or the farthest, when that slope is not positive), by one design
 *     step when it has only one point, by 4 across a flat stretch (C0 below the damping's
 *     share of C) and half a step when the slope says nothing; at most 4 and at least 0.1
 *     design steps, clamped to the bounds;
 *   - a pair within half its tolerance at the best point keeps its input (a step there is
 *     smaller than the packing's noise);
 *   - an input on a log scale (C0 spans decades) is stepped in log(x) but its secants are
 *     drawn in x (C grows about linearly with C0 once C0 matters: C = floor + k C0, a convex
 *     curve in log(C0) whose secants creep).
 * Verdicts: FOUND when a measured point meets every tolerance (the best such point: the least
 * largest error over tolerance); UNREACHABLE when a point at a bound of a pair's input, the
 * other outputs within 2 tolerances of their targets, is beyond the target by more than the
 * tolerance on the side the bound cannot cross (the range found is returned: least and most
 * of the pair's output over the points whose other outputs are near their targets);
 * NOT_MONOTONE when two points that differ in one input only contradict its increasing map by
 * more than their noise (2 standard errors combined); BUDGET when the design points allowed
 * are used up, and STALLED when the next point would repeat a measured one (the inputs'
 * rounding), both with the best point. Proposed inputs are rounded to `digits` significant
 * digits, so a point's inputs are exact, printable numbers (they name the run files and go
 * into the [material] block). Nothing is kept between calls: the same points give the same
 * step, so a calibration started again repeats its steps from the runs it finds.
 * Ownership: the caller owns every array. Thread safety: pure functions. Units: whatever the
 * caller uses, consistently (cdem-strain calibrate: N, degrees, MPa). */
#ifndef CDEM_CALIB_H
#define CDEM_CALIB_H

#include "cdem_error.h"

#include <stddef.h>

#define CDEM_CALIB_MAX_PAIRS 3

typedef struct {
    double lo, hi; /* the input's bounds, lo < hi (lo > 0 on a log scale) */
    int log_scale; /* 1: searched in log(x) */
    double first;  /* the input of the first point, within the bounds */
    double step;   /* the design step: added to x (linear) or to log(x) (log scale), > 0 */
    double target; /* the output wanted */
    double tol;    /* accepted |output - target|, > 0 */
    int fixed;     /* 1: the input never changes (the output is only reported) */
} cdem_calib_pair;

typedef struct {
    size_t n_pairs; /* 1..CDEM_CALIB_MAX_PAIRS */
    cdem_calib_pair pair[CDEM_CALIB_MAX_PAIRS];
    size_t budget; /* design points allowed, >= 1 */
    int digits;    /* significant digits of a proposed input, 2..12 */
} cdem_calib_problem;

/* One measured design point. */
typedef struct {
    double x[CDEM_CALIB_MAX_PAIRS];   /* the inputs */
    double y[CDEM_CALIB_MAX_PAIRS];   /* the outputs measured */
    double err[CDEM_CALIB_MAX_PAIRS]; /* their standard errors (>= 0; NaN taken as 0) */
} cdem_calib_point;

typedef enum {
    CDEM_CALIB_RUN,          /* measure the point x next */
    CDEM_CALIB_FOUND,        /* point `best` meets every tolerance */
    CDEM_CALIB_UNREACHABLE,  /* pair `pair`'s target is beyond its input's bound */
    CDEM_CALIB_NOT_MONOTONE, /* points bad[0], bad[1] contradict pair `pair`'s increasing map */
    CDEM_CALIB_BUDGET,       /* the budget is used up; `best` is the best point */
    CDEM_CALIB_STALLED,      /* the next point would repeat point bad[0]; `best` is the best */
} cdem_calib_verdict;

typedef struct {
    cdem_calib_verdict verdict;
    double x[CDEM_CALIB_MAX_PAIRS]; /* RUN: the next inputs (rounded) */
    size_t best;                    /* the point with the least largest error over tolerance */
    double best_score;              /* that error: max over pairs of |y - target| / tol */
    size_t pair;                    /* UNREACHABLE, NOT_MONOTONE: the pair concerned */
    double reach_lo, reach_hi;      /* UNREACHABLE: the pair's outputs measured, least and most */
    double reach_lo_x, reach_hi_x;  /* ... and the inputs they were measured at */
    int above;                      /* UNREACHABLE: 1 the target is above the range, 0 below */
    size_t at;                      /* UNREACHABLE: the point at the bound that shows it */
    size_t bad[2];                  /* NOT_MONOTONE: the two points; STALLED: bad[0] */
} cdem_calib_step;

/* Checks the problem: bounds, first inputs, steps, tolerances, budget, digits. Fails with
 * CDEM_ERR_RANGE naming the pair (by index) and the value. */
cdem_status cdem_calib_check(const cdem_calib_problem *p, cdem_error *err);

/* What to do after the n points measured (n = 0: the first point, the pairs' `first`).
 * Fails (CDEM_ERR_RANGE) only on a problem cdem_calib_check refuses or a point with a
 * non-finite input or output. */
cdem_status cdem_calib_next(const cdem_calib_problem *p, const cdem_calib_point *pts, size_t n,
                            cdem_calib_step *out, cdem_error *err);

/* x rounded to `digits` significant digits (0 stays 0). */
double cdem_calib_round(double x, int digits);

/* The name of a verdict ("run", "found", "unreachable", ...). */
const char *cdem_calib_verdict_name(cdem_calib_verdict v);

#endif
