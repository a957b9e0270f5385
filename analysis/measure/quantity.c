/* quantity: see quantity.h. The suggestion is the nearest name by the one edit distance
 * (common/suggest.h), offered whatever its distance: the message lists every name anyway. */
#include "quantity.h"

#include "suggest.h"

#include <stdio.h>
#include <string.h>

static const cdem_quantity quantities[] = {
    {"incr-disp-x", "Incremental horizontal displacement", "m", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_INCR_DISP, CDEM_QC_X, "x(k) - x(k-5)"},
    {"incr-disp-y", "Incremental vertical displacement", "m", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_INCR_DISP, CDEM_QC_Y, "y(k) - y(k-5)"},
    {"incr-disp-mag", "Incremental displacement magnitude", "m", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_INCR_DISP, CDEM_QC_MAG, "|u(k) - u(k-5)|"},
    {"total-disp-x", "Total horizontal displacement", "m", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_TOTAL_DISP, CDEM_QC_X, "x(k) - x(equil or birth)"},
    {"total-disp-y", "Total vertical displacement", "m", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_TOTAL_DISP, CDEM_QC_Y, "y(k) - y(equil or birth)"},
    {"total-disp-mag", "Total displacement magnitude", "m", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_TOTAL_DISP, CDEM_QC_MAG, "|x(k) - x(equil or birth)|"},
    {"uplift", "Uplift (+) and subsidence (-)", "m", CDEM_SCALE_SIGNED, 0, CDEM_QF_TOTAL_DISP,
     CDEM_QC_Y, "y(k) - y(equil or birth), signed colour scale"},
    {"incr-e1", "Incremental extension e1", "", CDEM_SCALE_MAGNITUDE, 0, CDEM_QF_INCR_STRAIN,
     CDEM_QC_E1, "S1 - 1"},
    {"incr-e3", "Incremental shortening -e3", "", CDEM_SCALE_MAGNITUDE, 0, CDEM_QF_INCR_STRAIN,
     CDEM_QC_E3NEG, "1 - S3"},
    {"incr-max-shear", "Incremental max. shear strain", "", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_INCR_STRAIN, CDEM_QC_MAXSHEAR, "(l1 - l3) / (2 sqrt(l1 l3))"},
    {"incr-dilation", "Incremental dilation", "", CDEM_SCALE_SIGNED, 0, CDEM_QF_INCR_STRAIN,
     CDEM_QC_DILATION, "S1 S3 - 1"},
    {"incr-rotation", "Incremental rotation (+ clockwise)", "rad", CDEM_SCALE_SIGNED, 0,
     CDEM_QF_INCR_STRAIN, CDEM_QC_ROTATION, "(dUx/dY - dUy/dX) / 2"},
    {"incr-s1-direction", "Incremental S1 direction", "deg", CDEM_SCALE_SIGNED, 0,
     CDEM_QF_INCR_STRAIN, CDEM_QC_ANGLE1, "direction of S1 in the deformed frame"},
    {"total-e1", "Total extension e1", "", CDEM_SCALE_MAGNITUDE, 0, CDEM_QF_TOTAL_STRAIN,
     CDEM_QC_E1, "S1 - 1"},
    {"total-e3", "Total shortening -e3", "", CDEM_SCALE_MAGNITUDE, 0, CDEM_QF_TOTAL_STRAIN,
     CDEM_QC_E3NEG, "1 - S3"},
    {"total-max-shear", "Total max. shear strain", "", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_TOTAL_STRAIN, CDEM_QC_MAXSHEAR, "(l1 - l3) / (2 sqrt(l1 l3))"},
    {"total-dilation", "Total dilation", "", CDEM_SCALE_SIGNED, 0, CDEM_QF_TOTAL_STRAIN,
     CDEM_QC_DILATION, "S1 S3 - 1"},
    {"total-s1-direction", "Total S1 direction", "deg", CDEM_SCALE_SIGNED, 0, CDEM_QF_TOTAL_STRAIN,
     CDEM_QC_ANGLE1, "direction of S1 in the deformed frame"},
    {"cum-e1", "Cumulative extension e1", "", CDEM_SCALE_MAGNITUDE, 0, CDEM_QF_CUM_STRAIN,
     CDEM_QC_E1, "sum of S1 - 1 over successive increments"},
    {"cum-e3", "Cumulative shortening -e3", "", CDEM_SCALE_MAGNITUDE, 0, CDEM_QF_CUM_STRAIN,
     CDEM_QC_E3NEG, "sum of 1 - S3 over successive increments"},
    {"cum-max-shear", "Cumulative max. shear strain", "", CDEM_SCALE_MAGNITUDE, 0,
     CDEM_QF_CUM_STRAIN, CDEM_QC_MAXSHEAR, "sum of max. shear strain over successive increments"},
    {"cum-dilation", "Cumulative dilation", "", CDEM_SCALE_SIGNED, 0, CDEM_QF_CUM_STRAIN,
     CDEM_QC_DILATION, "sum of S1 S3 - 1 over successive increments"},
    {"sxx", "Horizontal stress sxx", "N/m", CDEM_SCALE_MAGNITUDE, 1, CDEM_QF_STRESS, CDEM_QC_SXX,
     "stored sxx (compression positive)"},
    {"syy", "Vertical stress syy", "N/m", CDEM_SCALE_MAGNITUDE, 1, CDEM_QF_STRESS, CDEM_QC_SYY,
     "stored syy (compression positive)"},
    {"sxy", "Shear stress txy", "N/m", CDEM_SCALE_MAGNITUDE, 1, CDEM_QF_STRESS, CDEM_QC_SXY,
     "stored sxy"},
    {"sigma1", "Maximum principal stress s1", "N/m", CDEM_SCALE_MAGNITUDE, 1, CDEM_QF_STRESS,
     CDEM_QC_SIGMA1, "(sxx + syy)/2 + sqrt(((sxx - syy)/2)^2 + sxy^2)"},
    {"sigma3", "Minimum principal stress s3", "N/m", CDEM_SCALE_MAGNITUDE, 1, CDEM_QF_STRESS,
     CDEM_QC_SIGMA3, "(sxx + syy)/2 - sqrt(((sxx - syy)/2)^2 + sxy^2)"},
    {"max-shear-stress", "Maximum shear stress (s1 - s3)/2", "N/m", CDEM_SCALE_MAGNITUDE, 1,
     CDEM_QF_STRESS, CDEM_QC_SMAXSHEAR, "(sigma1 - sigma3) / 2"},
    {"sigma1-direction", "Direction of s1", "deg", CDEM_SCALE_SIGNED, 1, CDEM_QF_STRESS,
     CDEM_QC_SANGLE, "0.5 atan2(2 sxy, sxx - syy)"},
};

const cdem_quantity *cdem_quantity_table(size_t *count) {
    if (count)
        *count = sizeof quantities / sizeof quantities[0];
    return quantities;
}

cdem_status cdem_quantity_find(const char *name, const cdem_quantity **out, cdem_error *err) {
    size_t n;
    const cdem_quantity *t = cdem_quantity_table(&n);
    *out = NULL;
    if (!name)
        name = "";
    for (size_t i = 0; i < n; i++)
        if (strcmp(t[i].name, name) == 0) {
            *out = &t[i];
            return CDEM_OK;
        }
    char list[CDEM_ERROR_MSG_MAX / 2] = "";
    size_t pos = 0;
    for (size_t i = 0; i < n && pos < sizeof list; i++)
        pos += (size_t)snprintf(list + pos, sizeof list - pos, "%s%s", i ? ", " : "", t[i].name);
    /* A name without its family ("max-shear", "e1"): every family that has it, total first,
     * the one asked for most (issue 35, item 15: the nearest by spelling was cum-max-shear,
     * the rarest). Else the nearest name by spelling. */
    static const char *const families[] = {"total-", "incr-", "cum-"};
    char offer[256] = "";
    size_t at = 0, found = 0;
    for (size_t f = 0; f < sizeof families / sizeof families[0]; f++) {
        char full[128];
        snprintf(full, sizeof full, "%s%.60s", families[f], name);
        for (size_t i = 0; i < n; i++)
            if (strcmp(t[i].name, full) == 0 && at < sizeof offer)
                at += (size_t)snprintf(offer + at, sizeof offer - at, "%s'%s'", found++ ? ", " : "",
                                       full);
    }
    if (found == 0) {
        size_t best = 0, bestd = (size_t)-1;
        for (size_t i = 0; i < n; i++) {
            size_t d = cdem_edit_distance(name, t[i].name);
            if (d < bestd) {
                bestd = d;
                best = i;
            }
        }
        snprintf(offer, sizeof offer, "'%s'", t[best].name);
    }
    return CDEM_FAIL(err, CDEM_ERR_NOTFOUND,
                     "unknown quantity '%.60s'; did you mean %s? Valid quantities: %s", name, offer,
                     list);
}
