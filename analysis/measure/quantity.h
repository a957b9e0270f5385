/* quantity: the registry of every per-element quantity cdem-strain can compute and colour
 * by. One static const row per quantity (name, label, unit, colour scale, whether it needs
 * stress, and how it is computed); the CLI, the renderer, the limits and docs/analysis.md all
 * read it. Names are lower-case words joined by '-' ("total-max-shear"); "-e3" quantities are
 * the shortening -e3 (positive when shortened).
 * Ownership: rows are static const; pointers stay valid for the program's life.
 * Thread safety: read-only. Units: m (displacement), 1 (strain), rad (rotation), N/m (stress,
 * compression positive), deg (directions, counter-clockwise from +x, in (-90, 90]). */
#ifndef CDEM_QUANTITY_H
#define CDEM_QUANTITY_H

#include "cdem_error.h"

#include <stddef.h>

typedef enum {
    CDEM_SCALE_MAGNITUDE = 0, /* blue-green-red, low to high */
    CDEM_SCALE_SIGNED = 1,    /* blue-white-red, symmetric around zero */
} cdem_scale_kind;

typedef enum {
    CDEM_QF_INCR_DISP = 0, /* incremental displacement (k against k - 5) */
    CDEM_QF_TOTAL_DISP,    /* total displacement (k against the end of equilibration) */
    CDEM_QF_INCR_STRAIN,   /* incremental strain */
    CDEM_QF_TOTAL_STRAIN,  /* total strain */
    CDEM_QF_CUM_STRAIN,    /* cumulative strain (sum of successive pairs) */
    CDEM_QF_STRESS,        /* stress stored in the increment */
} cdem_quantity_family;

/* Components within a family. */
enum {
    CDEM_QC_X = 0, /* displacement: horizontal */
    CDEM_QC_Y,     /* displacement: vertical (uplift is total Y with a signed scale) */
    CDEM_QC_MAG,   /* displacement: magnitude */
};
enum {
    CDEM_QC_E1 = 0,   /* strain: S1 - 1 */
    CDEM_QC_E3NEG,    /* strain: -e3 */
    CDEM_QC_MAXSHEAR, /* strain: maximum shear strain */
    CDEM_QC_DILATION, /* strain: S1 S3 - 1 */
    CDEM_QC_ROTATION, /* strain: infinitesimal rotation, + clockwise */
    CDEM_QC_ANGLE1,   /* strain: direction of S1 in the deformed frame, deg */
};
enum {
    CDEM_QC_SXX = 0,   /* stress: sigma_xx */
    CDEM_QC_SYY,       /* stress: sigma_yy */
    CDEM_QC_SXY,       /* stress: tau_xy */
    CDEM_QC_SIGMA1,    /* stress: sigma1 */
    CDEM_QC_SIGMA3,    /* stress: sigma3 */
    CDEM_QC_SMAXSHEAR, /* stress: (sigma1 - sigma3) / 2 */
    CDEM_QC_SANGLE,    /* stress: direction of sigma1, deg */
};

typedef struct {
    const char *name;            /* command-line name, e.g. "total-max-shear" */
    const char *label;           /* colour-bar label, e.g. "Total max. shear strain" */
    const char *unit;            /* "m", "", "rad", "N/m" */
    cdem_scale_kind scale;       /* colour scale */
    int needs_stress;            /* 1: only for increments that store stress */
    cdem_quantity_family family; /* how it is computed */
    int component;               /* CDEM_QC_* within the family */
    const char *formula;         /* one line for docs and --help */
} cdem_quantity;

/* The whole table, in display order. */
const cdem_quantity *cdem_quantity_table(size_t *count);

/* Finds a quantity by name. Unknown names fail with CDEM_ERR_NOTFOUND and a message that
 * suggests the closest name ("did you mean ...?") and lists every valid one. */
cdem_status cdem_quantity_find(const char *name, const cdem_quantity **out, cdem_error *err);

#endif
