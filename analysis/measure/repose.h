/* repose: the angle of repose of a pile's final free surface, how well a line fits it, and
 * whether the pile has stopped moving.
 *
 * The free surface is sampled in vertical columns of width 2 x the largest free-element
 * radius, from the leftmost to the rightmost free element: each column's surface element
 * is its highest non-wall element (by top, y + radius; an element belongs to the column
 * holding its centre). Only the slope is fitted: columns whose top lies strictly between
 * lo + 10 % and lo + 90 % of the height drop (lo, hi = lowest and highest column tops) are
 * kept, which excludes the flat crest and the flat toe. The kept columns are split at
 * the crest (the highest column) into a left and a right flank; a flank is fitted when it
 * holds at least 2 columns and 25 % of the kept ones (so a pile collapsed to one side has
 * one flank, a mound two). A least-squares line top = intercept + slope x goes through
 * each fitted flank's tops; its angle is atan(|slope|); the result is the mean over the
 * fitted flanks weighted by their column counts.
 *
 * Fit quality: each fitted flank also gets the 95 % confidence half-width of its angle
 * (Student's t on the slope's standard error) and the angles of lines fitted through its
 * upper and lower halves (the columns split in x order; a slope that is convex or concave
 * has halves of different angles). A flank is a poor fit (CDEM_REPOSE_* flags) when it
 * has fewer than 6 columns, when the confidence half-width exceeds 3 degrees, when its rms
 * misfit exceeds 1.5 x the largest free radius, or when its halves differ by more than
 * 10 degrees: then the surface is not one straight slope and its angle depends on where
 * it is fitted.
 *
 * Motion: cdem_repose_motion_between compares two increments of a run element by element
 * (by id); cdem_repose_settled judges a series of angles and the last increment's motion:
 * the slope is at rest when the free elements moved on average less than 1 % of the
 * largest radius in the last increment and none left the model in it, and its angle is
 * stable when it varies by at most 2 degrees over the increments given (cdem-strain repose
 * gives those of the last third of the run).
 *
 * Spread: one collapse's angle depends on its packing (examples/calibration/repose-6c.md:
 * a standard deviation of 2-3 degrees over twelve packings), so a material's angle of
 * repose is the mean over several packings; cdem_repose_spread_of summarises the angles
 * of such runs (mean, sample standard deviation, the mean's standard error, range).
 * Ownership: the caller owns the states and arrays. Thread safety: pure functions; scratch
 * memory is allocated per call. Units: m; angles in degrees. */
#ifndef CDEM_REPOSE_H
#define CDEM_REPOSE_H

#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

/* Why a flank is a poor fit (cdem_repose_flank.poor, bits). */
enum {
    CDEM_REPOSE_FEW = 1 << 0,       /* fewer than CDEM_REPOSE_MIN_COLUMNS columns fitted */
    CDEM_REPOSE_UNCERTAIN = 1 << 1, /* 95 % confidence half-width > CDEM_REPOSE_MAX_CI_DEG */
    CDEM_REPOSE_ROUGH = 1 << 2,     /* rms misfit > CDEM_REPOSE_MAX_RMS_RADII largest radii */
    CDEM_REPOSE_CURVED = 1 << 3,    /* halves differ by more than CDEM_REPOSE_MAX_BEND_DEG */
};
#define CDEM_REPOSE_MIN_COLUMNS   6
#define CDEM_REPOSE_MAX_CI_DEG    3.0
#define CDEM_REPOSE_MAX_RMS_RADII 1.5
#define CDEM_REPOSE_MAX_BEND_DEG  10.0
/* At rest: mean displacement per increment below this fraction of the largest radius. */
#define CDEM_REPOSE_REST_FRACTION 0.01
/* Stable: the angle varies by at most this over the increments judged. */
#define CDEM_REPOSE_STABLE_DEG 2.0

/* One fitted flank of the surface. */
typedef struct {
    double angle_deg;        /* atan(|slope|), degrees, 0..90 */
    double slope, intercept; /* fitted line top = intercept + slope x (slope dimensionless) */
    double x_first, x_last;  /* m, x range of the fitted surface elements */
    size_t n;                /* surface elements in the fit, >= 2 (0: flank not fitted) */
    double residual_rms;     /* m, rms vertical distance of the fitted tops from the line */
    double angle_ci_deg;     /* 95 % confidence half-width of angle_deg; NaN when n < 3 */
    double angle_upper_deg;  /* angle of the upper half (the half nearer the crest); NaN when
                                n < 4 */
    double angle_lower_deg;  /* angle of the lower half; NaN when n < 4 */
    int poor;                /* CDEM_REPOSE_* bits; 0: a good fit */
} cdem_repose_flank;

typedef struct {
    double angle_deg;           /* angle of repose, degrees, 0..90 (weighted flank mean) */
    cdem_repose_flank flank[2]; /* 0: left of the crest, 1: right; n = 0 when not fitted */
    double column_width;        /* m, 2 x largest free radius */
    double r_max;               /* m, largest free radius */
    size_t n_columns;           /* columns holding a free element */
    size_t n_fitted;            /* surface elements in the fits (both flanks), >= 2 */
    double crest_x;             /* m, x of the highest surface element */
    int poor;                   /* union of the fitted flanks' poor bits */
} cdem_repose_result;

/* Measures the angle of repose of state s. Fails when s has no free elements, or fewer
 * than 2 surface columns on the slope (a flat or one-column surface). */
cdem_status cdem_repose_measure(const cdem_state *s, cdem_repose_result *res, cdem_error *err);

/* Writes into buf (size n, always terminated) why flank f is a poor fit, the reasons
 * separated by "; " (for example "the slope is curved: upper half 22.5 deg, lower half
 * 47.6 deg"), or "" when it is a good one. r_max is the largest free radius (m). */
void cdem_repose_poor_text(const cdem_repose_flank *f, double r_max, char *buf, size_t n);

/* Displacement of the free elements between two increments of one run. */
typedef struct {
    double mean, max; /* m, over the free elements present in both (0 when none) */
    size_t n_matched; /* free elements present in both, matched by id */
    size_t n_before;  /* free elements of the earlier increment */
    size_t n_after;   /* free elements of the later increment */
} cdem_repose_motion;

/* The motion of the free elements from state a to state b (matched by id). Fails on a
 * negative id. */
cdem_status cdem_repose_motion_between(const cdem_state *a, const cdem_state *b,
                                       cdem_repose_motion *m, cdem_error *err);

/* Whether a slope has settled. */
typedef struct {
    double angle_min, angle_max; /* deg, over the angles judged */
    size_t n;                    /* angles judged */
    int stable;                  /* n >= 2 and angle_max - angle_min <= CDEM_REPOSE_STABLE_DEG */
    int at_rest; /* last motion's mean < CDEM_REPOSE_REST_FRACTION x r_max, none lost */
} cdem_repose_settling;

/* Judges the angles (n of them, in degrees, NaN for an increment without a measurable slope,
 * which makes the series unstable) of the increments over a window and the motion `last`
 * of its last increment; r_max is the largest free radius (m). */
void cdem_repose_settled(const double *angles, size_t n, const cdem_repose_motion *last,
                         double r_max, cdem_repose_settling *out);

/* The angles of repose of several runs of one material (its packings). */
typedef struct {
    size_t n;                /* angles summarised (the finite ones given) */
    double mean_deg;         /* their mean; NaN when n = 0 */
    double sd_deg;           /* sample standard deviation (n - 1); NaN when n < 2 */
    double se_deg;           /* standard error of the mean, sd / sqrt(n); NaN when n < 2 */
    double min_deg, max_deg; /* range; NaN when n = 0 */
} cdem_repose_spread;

/* Summarises angles[0..n) (degrees; NaN entries, runs without a measure, are left out).
 * Fails only without memory for a copy of the finite angles. */
cdem_status cdem_repose_spread_of(const double *angles, size_t n, cdem_repose_spread *out,
                                  cdem_error *err);

#endif
