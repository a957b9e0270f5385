/* calib: see calib.h. Everything is computed afresh from the points on each call: the
 * search keeps no state, so a calibration that is stopped and started again takes the same
 * steps from the same measurements (cdem-strain calibrate resumes that way). The constants
 * below were chosen on the synthetic model of tests/test_calib.c, shaped like the default
 * assembly's measured maps. */
#include "calib.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* How far out a false-position step may go into its bracket: it stays within the inner
 * 80 %, so a strongly curved map cannot keep it on one side (regula falsi's slow end). */
#define CALIB_BRACKET_MARGIN 0.1
/* An extrapolation goes at most this many design steps, and at least this fraction of one. */
#define CALIB_MAX_STEPS 4.0
#define CALIB_MIN_STEP  0.1
/* Two points contradict an increasing map when the lower input's output exceeds the higher
 * one's by more than this many standard errors (combined). */
#define CALIB_NOISE_SIGMAS 2.0
/* A point shows a pair's reach when the other outputs are within this many tolerances. */
#define CALIB_NEAR 2.0
/* Points a step looks at (the budget is at most 32 in cdem-strain calibrate). */
#define MAX_POINTS_1D 64

const char *cdem_calib_verdict_name(cdem_calib_verdict v) {
    switch (v) {
    case CDEM_CALIB_RUN:
        return "run";
    case CDEM_CALIB_FOUND:
        return "found";
    case CDEM_CALIB_UNREACHABLE:
        return "unreachable";
    case CDEM_CALIB_NOT_MONOTONE:
        return "not monotone";
    case CDEM_CALIB_BUDGET:
        return "budget used up";
    case CDEM_CALIB_STALLED:
        return "stalled";
    }
    return "unknown";
}

double cdem_calib_round(double x, int digits) {
    if (x == 0 || !isfinite(x))
        return x;
    char buf[64];
    snprintf(buf, sizeof buf, "%.*e", digits - 1, x);
    double r;
    return sscanf(buf, "%lf", &r) == 1 ? r : x;
}

cdem_status cdem_calib_check(const cdem_calib_problem *p, cdem_error *err) {
    if (p->n_pairs < 1 || p->n_pairs > CDEM_CALIB_MAX_PAIRS)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "calibration: %zu pairs: must be 1 to %d", p->n_pairs,
                         CDEM_CALIB_MAX_PAIRS);
    if (p->budget < 1)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "calibration: a budget of 0 design points");
    if (p->digits < 2 || p->digits > 12)
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "calibration: %d significant digits: must be 2 to 12",
                         p->digits);
    for (size_t k = 0; k < p->n_pairs; k++) {
        const cdem_calib_pair *q = &p->pair[k];
        if (!isfinite(q->first))
            return CDEM_FAIL(err, CDEM_ERR_RANGE, "calibration: pair %zu: first input %g", k + 1,
                             q->first);
        if (q->fixed)
            continue;
        if (!(isfinite(q->lo) && isfinite(q->hi) && q->lo < q->hi))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "calibration: pair %zu: bounds %g to %g: need lo < hi, both finite",
                             k + 1, q->lo, q->hi);
        if (q->log_scale && !(q->lo > 0))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "calibration: pair %zu: lower bound %g on a log scale: must be > 0",
                             k + 1, q->lo);
        if (!(q->first >= q->lo && q->first <= q->hi))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "calibration: pair %zu: first input %g outside its bounds %g to %g",
                             k + 1, q->first, q->lo, q->hi);
        if (!(q->step > 0 && isfinite(q->step)))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "calibration: pair %zu: design step %g: must be > 0", k + 1, q->step);
        if (!(q->tol > 0 && isfinite(q->tol)) || !isfinite(q->target))
            return CDEM_FAIL(err, CDEM_ERR_RANGE,
                             "calibration: pair %zu: target %g +- %g: need a finite target and "
                             "a tolerance > 0",
                             k + 1, q->target, q->tol);
    }
    return CDEM_OK;
}

/* The search coordinate of input x of pair q, and back. */
static double to_t(const cdem_calib_pair *q, double x) {
    return q->log_scale ? log(x) : x;
}
static double from_t(const cdem_calib_pair *q, double t) {
    return q->log_scale ? exp(t) : t;
}

static double err_of(const cdem_calib_point *pt, size_t k) {
    double e = pt->err[k];
    return isfinite(e) && e > 0 ? e : 0;
}

/* The largest |y - target| / tol over the searched pairs. */
static double score(const cdem_calib_problem *p, const cdem_calib_point *pt) {
    double s = 0;
    for (size_t k = 0; k < p->n_pairs; k++)
        if (!p->pair[k].fixed)
            s = fmax(s, fabs(pt->y[k] - p->pair[k].target) / p->pair[k].tol);
    return s;
}

/* 1 when points i and j differ in input k only (every other searched input equal). */
static int only_differ_in(const cdem_calib_problem *p, const cdem_calib_point *a,
                          const cdem_calib_point *b, size_t k) {
    for (size_t j = 0; j < p->n_pairs; j++)
        if (j != k && !p->pair[j].fixed && a->x[j] != b->x[j])
            return 0;
    return a->x[k] < b->x[k];
}

/* Two points i, j differing only in input k (x_i < x_j) whose outputs of pair k contradict
 * an increasing map by more than their noise; 1 when found. Points that differ in another
 * input too are not compared: that input's effect (mu moves C a lot) is no contradiction. */
static int find_violation(const cdem_calib_problem *p, const cdem_calib_point *pts, size_t n,
                          size_t k, size_t bad[2]) {
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            if (!only_differ_in(p, &pts[i], &pts[j], k))
                continue;
            double noise = CALIB_NOISE_SIGMAS * hypot(err_of(&pts[i], k), err_of(&pts[j], k));
            if (pts[i].y[k] - pts[j].y[k] > noise) {
                bad[0] = i;
                bad[1] = j;
                return 1;
            }
        }
    return 0;
}

/* 1 when point pt's other searched outputs (all but k) are within CALIB_NEAR x their
 * tolerance: the point shows what pair k can reach where the others are on target. */
static int others_near(const cdem_calib_problem *p, const cdem_calib_point *pt, size_t k) {
    for (size_t j = 0; j < p->n_pairs; j++)
        if (j != k && !p->pair[j].fixed &&
            fabs(pt->y[j] - p->pair[j].target) > CALIB_NEAR * p->pair[j].tol)
            return 0;
    return 1;
}

/* UNREACHABLE for pair k: a point at one of its input's bounds, the other outputs near
 * their targets, whose output lies beyond the target by more than the tolerance on the side
 * the bound cannot cross (above it at the lower bound, below it at the upper). The range
 * reported is that of the points whose other outputs are near their targets. */
static int unreachable(const cdem_calib_problem *p, const cdem_calib_point *pts, size_t n, size_t k,
                       cdem_calib_step *out) {
    const cdem_calib_pair *q = &p->pair[k];
    const double t_lo = to_t(q, q->lo), t_hi = to_t(q, q->hi), eps = 1e-9 * (t_hi - t_lo);
    int found = 0, above = 0;
    size_t at = 0;
    for (size_t i = 0; i < n && !found; i++) {
        if (!others_near(p, &pts[i], k))
            continue;
        const double t = to_t(q, pts[i].x[k]), y = pts[i].y[k];
        if (t <= t_lo + eps && y > q->target + q->tol)
            found = 1, above = 0, at = i;
        else if (t >= t_hi - eps && y < q->target - q->tol)
            found = 1, above = 1, at = i;
    }
    if (!found)
        return 0;
    long lo = -1, hi = -1;
    for (size_t i = 0; i < n; i++) {
        if (!others_near(p, &pts[i], k))
            continue;
        if (lo < 0 || pts[i].y[k] < pts[lo].y[k])
            lo = (long)i;
        if (hi < 0 || pts[i].y[k] > pts[hi].y[k])
            hi = (long)i;
    }
    out->verdict = CDEM_CALIB_UNREACHABLE;
    out->pair = k;
    out->above = above;
    out->at = at;
    out->reach_lo = pts[lo].y[k];
    out->reach_lo_x = pts[lo].x[k];
    out->reach_hi = pts[hi].y[k];
    out->reach_hi_x = pts[hi].x[k];
    return 1;
}

/* Where the line through (t1, y1) and (t2, y2) reaches target, in the search coordinate;
 * the line is drawn in x itself, not in log(x): C rises about linearly with C0 once C0
 * matters (C = floor + k C0), which in log(C0) is a convex curve whose secants creep.
 * -INFINITY when the line reaches it at x <= 0 (beyond any lower bound of a log scale). */
static double secant_t(const cdem_calib_pair *q, double t1, double y1, double t2, double y2,
                       double target) {
    const double x1 = from_t(q, t1), x2 = from_t(q, t2);
    const double x = x1 + (target - y1) * (x1 - x2) / (y1 - y2);
    if (q->log_scale && !(x > 0))
        return -INFINITY;
    return to_t(q, x);
}

/* The one-dimensional proposal for pair q from the points' inputs t (search coordinate) and
 * outputs y (taken at the other inputs of the step, see cross_effects), best the point
 * nearest the target (calib.h: keep, false position in a bracket, or extrapolation). */
static void propose_1d(const cdem_calib_pair *q, const double *t, const double *y, size_t n,
                       size_t best, double *t_next) {
    const double target = q->target, t_lo = to_t(q, q->lo), t_hi = to_t(q, q->hi);
    const double eps = 1e-9 * (t_hi - t_lo);
    if (fabs(y[best] - target) <= 0.5 * q->tol) {
        *t_next = t[best]; /* a step would be smaller than the noise */
        return;
    }
    /* the nearest points below the target (highest input) and above it (lowest input) */
    long below = -1, above = -1;
    for (size_t i = 0; i < n; i++) {
        if (y[i] < target && (below < 0 || t[i] > t[below] + eps ||
                              (fabs(t[i] - t[below]) <= eps && y[i] > y[below])))
            below = (long)i;
        if (y[i] >= target && (above < 0 || t[i] < t[above] - eps ||
                               (fabs(t[i] - t[above]) <= eps && y[i] < y[above])))
            above = (long)i;
    }
    if (below >= 0 && above >= 0) {
        const double ta = t[below], tb = t[above], ya = y[below], yb = y[above];
        if (ta >= tb - eps) {
            *t_next = 0.5 * (ta + tb); /* the bracket is inverted within the noise */
            return;
        }
        /* the secant through the two points nearest the target, when it falls inside the
         * bracket's inner 80 % (a far bracket end, such as a bound, would make false
         * position creep); else false position, kept within the inner 80 % */
        long n1 = -1, n2 = -1;
        for (size_t i = 0; i < n; i++) {
            if (n1 < 0 || fabs(y[i] - target) < fabs(y[n1] - target)) {
                n2 = n1;
                n1 = (long)i;
            } else if (fabs(t[i] - t[n1]) > eps &&
                       (n2 < 0 || fabs(y[i] - target) < fabs(y[n2] - target))) {
                n2 = (long)i;
            }
        }
        const double w = tb - ta, in_lo = ta + CALIB_BRACKET_MARGIN * w,
                     in_hi = tb - CALIB_BRACKET_MARGIN * w;
        if (n2 >= 0 && fabs(t[n1] - t[n2]) > eps && y[n1] != y[n2]) {
            const double ts = secant_t(q, t[n1], y[n1], t[n2], y[n2], target);
            if (ts >= in_lo && ts <= in_hi) {
                *t_next = ts;
                return;
            }
        }
        const double tf = secant_t(q, ta, ya, tb, yb, target); /* false position */
        *t_next = fmin(fmax(tf, in_lo), in_hi);
        return;
    }
    /* every point on one side: extrapolate from the nearest towards the target */
    const int up = above < 0; /* all below: the input must rise */
    const size_t a = (size_t)(up ? below : above);
    /* the secant through the nearest point and the next one on the same side; when that
     * slope is not positive (noise, or the other input moved), through the nearest and
     * the farthest on that side */
    long b = -1, f = -1;
    for (size_t i = 0; i < n; i++) {
        if (!(up ? t[i] < t[a] - eps : t[i] > t[a] + eps))
            continue;
        if (b < 0 || (up ? t[i] > t[b] : t[i] < t[b]))
            b = (long)i;
        if (f < 0 || (up ? t[i] < t[f] : t[i] > t[f]))
            f = (long)i;
    }
    double dt = q->step;
    if (b >= 0) {
        long use = (y[a] - y[b]) / (t[a] - t[b]) > 0 ? b : f;
        const double slope = (y[a] - y[use]) / (t[a] - t[use]);
        /* a flat or contrary slope over a design step or more says the points lie where
         * the input hardly matters (C0 below the damping's share of C): leave that region
         * fast; over less it says nothing: a probe of half a design step */
        dt = slope > 0 ? fabs(secant_t(q, t[a], y[a], t[use], y[use], target) - t[a])
             : fabs(t[a] - t[use]) >= q->step - eps ? CALIB_MAX_STEPS * q->step
                                                    : 0.5 * q->step;
        if (!isfinite(dt))
            dt = CALIB_MAX_STEPS * q->step;
    }
    dt = fmin(fmax(dt, CALIB_MIN_STEP * q->step), CALIB_MAX_STEPS * q->step);
    *t_next = up ? fmin(t[a] + dt, t_hi) : fmax(t[a] - dt, t_lo);
}

cdem_status cdem_calib_next(const cdem_calib_problem *p, const cdem_calib_point *pts, size_t n,
                            cdem_calib_step *out, cdem_error *err) {
    CDEM_TRY(cdem_calib_check(p, err));
    memset(out, 0, sizeof *out);
    for (size_t i = 0; i < n; i++)
        for (size_t k = 0; k < p->n_pairs; k++)
            if (!isfinite(pts[i].x[k]) || !isfinite(pts[i].y[k]) ||
                (p->pair[k].log_scale && !p->pair[k].fixed && !(pts[i].x[k] > 0)))
                return CDEM_FAIL(err, CDEM_ERR_RANGE,
                                 "calibration: point %zu, pair %zu: input %g, output %g: "
                                 "must be finite (the input > 0 on a log scale)",
                                 i + 1, k + 1, pts[i].x[k], pts[i].y[k]);
    if (n == 0) {
        out->verdict = CDEM_CALIB_RUN;
        for (size_t k = 0; k < p->n_pairs; k++)
            out->x[k] = cdem_calib_round(p->pair[k].first, p->digits);
        return CDEM_OK;
    }
    size_t best = 0;
    for (size_t i = 1; i < n; i++)
        if (score(p, &pts[i]) < score(p, &pts[best]))
            best = i;
    out->best = best;
    out->best_score = score(p, &pts[best]);
    if (out->best_score <= 1) {
        out->verdict = CDEM_CALIB_FOUND;
        return CDEM_OK;
    }
    for (size_t k = 0; k < p->n_pairs; k++)
        if (!p->pair[k].fixed && find_violation(p, pts, n, k, out->bad)) {
            out->verdict = CDEM_CALIB_NOT_MONOTONE;
            out->pair = k;
            return CDEM_OK;
        }
    for (size_t k = 0; k < p->n_pairs; k++)
        if (!p->pair[k].fixed && unreachable(p, pts, n, k, out))
            return CDEM_OK;
    if (n >= p->budget) {
        out->verdict = CDEM_CALIB_BUDGET;
        return CDEM_OK;
    }
    /* each searched pair steps on the points where the other outputs are near their
     * targets (the other inputs about where they must end: C depends on mu as much as on
     * C0), or on all points when fewer than two such points differ in its input; points of
     * the same input are replicates, their outputs averaged (a lucky packing must not hold
     * an input where its neighbours say it is wrong) */
    double t_next[CDEM_CALIB_MAX_PAIRS] = {0};
    double t[MAX_POINTS_1D], y[MAX_POINTS_1D];
    size_t count[MAX_POINTS_1D];
    for (size_t k = 0; k < p->n_pairs; k++) {
        const cdem_calib_pair *q = &p->pair[k];
        if (q->fixed)
            continue;
        const double t_best = to_t(q, pts[best].x[k]);
        for (int subset = 1; subset >= 0; subset--) {
            size_t m = 0;
            for (size_t i = 0; i < n; i++) {
                if (subset && i != best && !others_near(p, &pts[i], k))
                    continue;
                const double ti = to_t(q, pts[i].x[k]);
                size_t j = 0;
                while (j < m && t[j] != ti)
                    j++;
                if (j == m) {
                    if (m == MAX_POINTS_1D)
                        continue;
                    t[m] = ti;
                    y[m] = 0;
                    count[m++] = 0;
                }
                y[j] += pts[i].y[k];
                count[j]++;
            }
            if (subset && m < 2)
                continue;
            /* nb: the best point's input (always among them), its outputs averaged */
            size_t nb = 0;
            for (size_t j = 0; j < m; j++) {
                y[j] /= (double)count[j];
                if (t[j] == t_best)
                    nb = j;
            }
            propose_1d(q, t, y, m, nb, &t_next[k]);
            break;
        }
    }
    for (size_t k = 0; k < p->n_pairs; k++) {
        const cdem_calib_pair *q = &p->pair[k];
        if (q->fixed) {
            out->x[k] = cdem_calib_round(q->first, p->digits);
            continue;
        }
        double x = cdem_calib_round(from_t(q, t_next[k]), p->digits);
        out->x[k] = fmin(fmax(x, q->lo), q->hi);
    }
    for (size_t i = 0; i < n; i++) {
        size_t same = 0;
        for (size_t k = 0; k < p->n_pairs; k++)
            same += pts[i].x[k] == out->x[k];
        if (same == p->n_pairs) {
            out->verdict = CDEM_CALIB_STALLED;
            out->bad[0] = i;
            return CDEM_OK;
        }
    }
    out->verdict = CDEM_CALIB_RUN;
    return CDEM_OK;
}
