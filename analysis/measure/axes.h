/* axes: principal strain, maximum-shear and principal stress directions on a regular grid,
 * for drawing (the renderer draws constant-length segments; only directions are given).
 *
 * Grid: nodes spaced `spacing` (default 2 x the largest radius of the current state) over
 * the current state's bounding box, in the current (deformed) frame. A node is kept when its
 * nearest element is a non-wall element within one largest radius of it (so no axes on
 * walls or in the air above the surface). Strain axes: the elements within `spacing` of the
 * node in the current state, wall elements excluded, fitted u = t + G (X - Xmean) by least
 * squares on their reference positions (cdem_strain_fit); angles are those of S1 and S3 in
 * the deformed frame and the two lines at +-45 degrees from S1 (maximum shear directions;
 * exact for infinitesimal strain). Stress axes: principal directions of the mean stress
 * tensor of those elements. Angles in degrees counter-clockwise from +x, in (-90, 90].
 * Ownership: cdem_axes owns its arrays (cdem_axes_free accepts NULL). Thread safety: pure. */
#ifndef CDEM_AXES_H
#define CDEM_AXES_H

#include "cdem_error.h"
#include "state.h"

#include <stddef.h>

typedef struct {
    size_t n;        /* nodes kept */
    double spacing;  /* grid spacing, m */
    double *x, *y;   /* node position, m */
    double *angle1;  /* S1 (or sigma1) direction, deg */
    double *angle3;  /* S3 (or sigma3) direction, deg (angle1 +- 90) */
    double *shear_a; /* first maximum-shear direction, deg (angle1 + 45, wrapped) */
    double *shear_b; /* second maximum-shear direction, deg (angle1 - 45, wrapped) */
    double *value;   /* max. shear strain (strain axes) or (s1 - s3)/2 (stress axes) */
} cdem_axes;

void cdem_axes_free(cdem_axes *a);

/* Strain axes of cur against ref (elements matched by id). spacing <= 0: default. Nodes
 * whose fit is undefined or isotropic are left out. */
cdem_status cdem_axes_strain(const cdem_state *ref, const cdem_state *cur, double spacing,
                             cdem_axes *out, cdem_error *err);

/* Stress axes of cur (which must have stress: CDEM_ERR_INVALID otherwise). */
cdem_status cdem_axes_stress(const cdem_state *cur, double spacing, cdem_axes *out,
                             cdem_error *err);

#endif
