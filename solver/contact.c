/* contact: see contact.h. Only set-up code lives here; the per-pair law is inline in the
 * header so the force loop in integrate.c can inline it. */
#include "contact.h"

#include "state.h"

static const char *const class_names[CDEM_CLASS_COUNT] = {"element", "wall", "fault"};

const char *cdem_contact_class_name(int cls) {
    if (cls < 0 || cls >= CDEM_CLASS_COUNT)
        return "none";
    return class_names[cls];
}

int cdem_contact_class(uint32_t flags_i, uint32_t flags_j) {
    if ((flags_i | flags_j) & CDEM_FLAG_FOOTWALL)
        return -1;
    if ((flags_i & CDEM_FLAGS_BOUNDARY) && (flags_j & CDEM_FLAGS_BOUNDARY))
        return -1;
    const uint32_t f = flags_i | flags_j;
    if (f & (CDEM_FLAG_FAULT | CDEM_FLAG_MYLAR))
        return CDEM_CLASS_FAULT;
    if (f & CDEM_FLAG_WALL)
        return CDEM_CLASS_WALL;
    return CDEM_CLASS_ELEMENT;
}

/* Checks material.<cls>_<key> (or model.<key> when cls is NULL). */
static cdem_status check_value(const char *cls, const char *key, double v, int positive,
                               cdem_error *err) {
    if (!isfinite(v) || v < 0.0 || (positive && v == 0.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "contact law: %s%s%s%s = %g: must be a finite number %s 0",
                         cls ? "material." : "model.", cls ? cls : "", cls ? "_" : "", key, v,
                         positive ? ">" : ">=");
    return CDEM_OK;
}

cdem_status cdem_contact_law_init(cdem_contact_law *law, const cdem_params *p, double kn, double ks,
                                  cdem_error *err) {
    if (!law || !p)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_contact_law_init: NULL argument");
    CDEM_TRY(check_value(NULL, "kn", kn, 1, err));
    CDEM_TRY(check_value(NULL, "ks", ks, 0, err));
    const cdem_contact_material *mats[CDEM_CLASS_COUNT] = {&p->element, &p->wall, &p->fault};
    law->model = p->material;
    law->first_slip = p->first_slip ? 1 : 0;
    law->kn = kn;
    law->ks = ks;
    law->max_breaking_strain = 0.0;
    if (p->material != CDEM_MATERIAL_GRANULAR && p->material != CDEM_MATERIAL_BONDED)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "contact law: material.model = %d: must be granular or bonded",
                         (int)p->material);
    for (int c = 0; c < CDEM_CLASS_COUNT; c++) {
        const char *sec = class_names[c];
        CDEM_TRY(check_value(sec, "friction", mats[c]->friction, 0, err));
        CDEM_TRY(check_value(sec, "cohesion", mats[c]->cohesion, 0, err));
        law->friction[c] = mats[c]->friction;
        law->cohesion[c] = mats[c]->cohesion;
        law->breaking_strain[c] = mats[c]->breaking_strain;
        if (p->material == CDEM_MATERIAL_BONDED) {
            CDEM_TRY(check_value(sec, "breaking_strain", mats[c]->breaking_strain, 1, err));
            if (mats[c]->breaking_strain > law->max_breaking_strain)
                law->max_breaking_strain = mats[c]->breaking_strain;
        }
    }
    return CDEM_OK;
}
