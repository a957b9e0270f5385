/* wedge: accretionary-wedge measurements of a detachment run, per increment.
 *
 * Against the reference state (the end of equilibration) the surface is sampled in columns
 * (common/surface.h) of width 2 x the largest free radius from the material's left face;
 * the moving wall is the CDEM_FLAG_MOVING wall right of the material's middle (the right
 * wall; with detachment_walls = both the wedge is measured from the right wall). Per
 * increment: wedge height, wedge length (the deformed zone), surface taper, area change
 * and the mean wall/base forces of the time series; exact definitions in docs/analysis.md
 * ("Wedge") and at the fields of cdem_wedge_row.
 * Ownership: cdem_wedge_ref holds no pointers; rows are malloc'd for the caller; states
 * are borrowed for a call. Thread safety: pure functions (scratch memory per call).
 * Units: m, m^2 per metre of thickness, degrees, N (per metre, as the time series). */
#ifndef CDEM_WEDGE_H
#define CDEM_WEDGE_H

#include "analysis.h"
#include "cdem_error.h"
#include "h5format.h"
#include "state.h"

#include <stddef.h>
#include <stdio.h>

/* Options of the measurement. Zero-initialise for the defaults. */
typedef struct {
    double threshold; /* m, deformed-zone threshold (displacement and surface rise); 0 =
                         default: the mean free-element diameter of the reference; >= 0 */
} cdem_wedge_options;

/* What the reference state fixes for every increment. */
typedef struct {
    double x_left;       /* m, left face of the material: min (x - r) over free elements */
    double column_width; /* m, 2 x the largest free radius, > 0 */
    size_t n_columns;    /* columns from x_left to the reference wall face, >= 1 */
    double y_base;       /* m, bottom of the material: min (y - r) over free elements */
    double surface0;     /* m, initial surface height: mean of the column tops */
    double top0;         /* m, highest column top of the reference (height origin) */
    double thickness0;   /* m, surface0 - y_base, > 0 */
    double wall_x0;      /* m, inner face of the moving wall: min (x - r) of its elements */
    double length0;      /* m, initial length wall_x0 - x_left, > 0 */
    double area0;        /* m^2 per m, area under the column tops between the faces */
    double threshold;    /* m, the threshold in use (option or mean diameter), > 0 */
} cdem_wedge_ref;

/* One increment's measurements (NaN where undefined). */
typedef struct {
    int number;                 /* increment number */
    long step;                  /* time step of the increment */
    double shortening;          /* m, net displacement of the increment (total shortening) */
    double shortening_percent;  /* 100 x shortening / length0 */
    double height;              /* m, highest column top - top0 (0 at the reference) */
    double length;              /* m, wall face - front_x (0 when nothing is deformed) */
    double length_thickened;    /* m, wall face - the left edge of the farthest column whose
                                   top rose by more than the threshold (0: none) */
    double taper_deg;           /* degrees, atan of the least-squares slope of the column
                                   tops over the thickened zone (positive: rising towards
                                   the wall); NaN with fewer than 2 columns */
    double area_change;         /* m^2 per m, area under the column tops - area0 */
    double area_change_percent; /* 100 x area_change / area0 */
    double wall_force_x;        /* N, mean boundary_force_x of the series samples of the
                                   increment (steps after the previous increment up to this
                                   one; the nearest sample when none); NaN without series */
    double wall_force_y;        /* N, same for boundary_force_y */
    double base_force_x;        /* N, same for base_force_x (basal shear) */
    double base_force_y;        /* N, same for base_force_y (basal normal force) */
    double left_wall_force_x;   /* N, same for left_wall_force_x (the left lateral wall's
                                   own push: a backstop, or a moving wall of a two-sided
                                   shortening); NaN for files from before the column */
    double left_wall_force_y;   /* N, same for left_wall_force_y */
    double right_wall_force_x;  /* N, same for right_wall_force_x */
    double right_wall_force_y;  /* N, same for right_wall_force_y */
    double front_x;             /* m, left edge of the farthest deformed column (NaN: none) */
    double wall_x;              /* m, inner face of the moving wall */
    size_t n_fitted;            /* columns in the taper fit */
} cdem_wedge_row;

/* Fixes the reference from state ref (the end of equilibration). Fails when ref has no free
 * elements or no moving wall right of them, or the option threshold is negative/not finite. */
cdem_status cdem_wedge_reference(const cdem_state *ref, const cdem_wedge_options *opt,
                                 cdem_wedge_ref *r, cdem_error *err);

/* Measures state cur (elements matched with ref by id) into row (number, step, shortening
 * and forces are left to the caller: cdem_wedge_forces). */
cdem_status cdem_wedge_measure(const cdem_wedge_ref *r, const cdem_state *ref,
                               const cdem_state *cur, cdem_wedge_row *row, cdem_error *err);

/* Mean forces over the samples with step_from < step <= step_to (the nearest sample to
 * step_to when none; NaN when n = 0) into row's four force fields. */
void cdem_wedge_forces(const cdem_series_sample *smp, size_t n, long step_from, long step_to,
                       cdem_wedge_row *row);

/* Every increment from the end of equilibration to the last (first/last as indices; first
 * below the end of equilibration is raised to it): *rows malloc'd, *n_rows set. Fails
 * unless the context's parameters say boundary.mode = detachment. */
cdem_status cdem_wedge_analyse(cdem_analysis *a, const cdem_wedge_options *opt, size_t first,
                               size_t last, cdem_wedge_row **rows, size_t *n_rows,
                               cdem_wedge_ref *ref, cdem_error *err);

/* Writes the CSV (header line, then one row per increment, %.10g; NaN as "nan"). */
cdem_status cdem_wedge_write_csv(FILE *f, const cdem_wedge_row *rows, size_t n, cdem_error *err);

/* The CSV header (column names, comma-separated, no newline). */
const char *cdem_wedge_csv_header(void);

#endif
