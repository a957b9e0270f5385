/* contact: see contact.h. Only set-up code lives here; the per-pair kernel is inline in the
 * header so the force pass (solver/step/force.c) can inline it. */
#include "contact.h"

#include "checkpoint.h"
#include "model.h"
#include "state.h"

#include <string.h>

/* the laws' setup functions (common/laws/law.h) */
#define CDEM_LAW_SETUP
#include "laws/laws.def"
#undef CDEM_LAW_SETUP

/* What a law has of its own (its CDEM_LAW_STATE row; a law without one: nothing). */
typedef struct {
    int coefficients, slots;
    cdem_status (*setup)(const cdem_params *p, double *coef, cdem_error *err);
} law_state;

#define CDEM_LAW_STATE(ID, coefficients, slots, setup)                                             \
    _Static_assert((coefficients) >= 0 && (coefficients) <= CDEM_LAW_MAX_COEFFICIENTS &&           \
                       (slots) >= 0 && ((coefficients) == 0) == ((setup) == NULL),                 \
                   "law " #ID ": 0..CDEM_LAW_MAX_COEFFICIENTS coefficients, slots >= 0, and a "    \
                   "setup exactly when it has coefficients");
#include "laws/laws.def"
#undef CDEM_LAW_STATE

static const law_state law_states[CDEM_LAW_COUNT] = {
#define CDEM_LAW_STATE(ID, coefficients, slots, setup)                                             \
    [CDEM_LAW_##ID] = {coefficients, slots, setup},
#include "laws/laws.def"
#undef CDEM_LAW_STATE
};

static const char *const class_names[CDEM_CLASS_TOTAL] = {"element",
                                                          "wall",
                                                          "fault",
                                                          "base",
                                                          "element (weak)",
                                                          "element (layered)",
                                                          "element (layered, weak)",
                                                          "element (flexural slip)"};

const char *cdem_contact_class_name(int cls) {
    if (cls < 0 || cls >= CDEM_CLASS_TOTAL)
        return "none";
    return class_names[cls];
}

int cdem_contact_class(uint32_t flags_i, uint32_t flags_j) {
    /* a pair with a process's element is the process's (process/process.h), never the pair
     * list's */
    if ((flags_i | flags_j) & (CDEM_FLAG_FOOTWALL | CDEM_FLAGS_PROCESS))
        return -1;
    if ((flags_i & CDEM_FLAGS_BOUNDARY) && (flags_j & CDEM_FLAGS_BOUNDARY))
        return -1;
    const uint32_t f = flags_i | flags_j;
    if (f & (CDEM_FLAG_FAULT | CDEM_FLAG_MYLAR))
        return CDEM_CLASS_FAULT;
    if (f & CDEM_FLAG_WALL)
        return (f & CDEM_FLAG_BASE) ? CDEM_CLASS_BASE : CDEM_CLASS_WALL;
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
    cdem_contact_material base;
    cdem_params_base_material(p, &base);
    const cdem_contact_material *mats[CDEM_CLASS_COUNT] = {&p->element, &p->wall, &p->fault, &base};
    law->model = p->material;
    law->first_slip = p->first_slip ? 1 : 0;
    if ((int)p->granular_law < 0 || p->granular_law >= CDEM_LAW_COUNT) {
        char words[256];
        cdem_params_join_choices("material", "granular_law", words, sizeof words);
        return CDEM_FAIL(err, CDEM_ERR_RANGE, "contact law: material.granular_law = %d: must be %s",
                         (int)p->granular_law, words);
    }
    if (p->cohesive_contacts != CDEM_COHESIVE_EQUILIBRATED &&
        p->cohesive_contacts != CDEM_COHESIVE_FORMED &&
        p->cohesive_contacts != CDEM_COHESIVE_INITIAL)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "contact law: material.cohesive_contacts = %d: must be equilibrated, "
                         "formed or initial",
                         (int)p->cohesive_contacts);
    if (!(p->settling_friction >= 0.0 && p->settling_friction <= 1.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "contact law: material.settling_friction = %g: must be 0..1",
                         p->settling_friction);
    law->granular = p->granular_law;
    law->cohesive_rule = p->cohesive_contacts;
    law->settling_friction = p->settling_friction;
    law->cohesive_new = 0;
    law->kn = kn;
    law->ks = ks;
    law->max_breaking_strain = 0.0;
    law->flexural_slip = !p->flexural_slip                                 ? 0
                         : p->flexural_slip_style == CDEM_FLEX_WEAK_LAYERS ? 2
                                                                           : 1;
    law->layered_friction = p->layered_friction ? 1 : 0;
    /* the granular law's own coefficients and history slots (none for the bonded model) */
    const law_state *own = &law_states[p->granular_law];
    memset(law->coef, 0, sizeof law->coef);
    law->coefficient_count = 0;
    law->slot_count = 0;
    if (p->material == CDEM_MATERIAL_GRANULAR) {
        law->coefficient_count = own->coefficients;
        law->slot_count = own->slots;
        if (own->setup)
            CDEM_TRY(own->setup(p, law->coef, err));
    }
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
    /* heterogeneity classes (element-element refinements) */
    const double ws = p->weak_interval != CDEM_WEAK_OFF ? p->weak_strength_percent / 100.0 : 1.0;
    if (!isfinite(ws) || ws < 0.0 || ws > 1.0)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "contact law: heterogeneity.weak_strength_percent = %g: must be 0..100",
                         p->weak_strength_percent);
    const double lf = p->layered_friction ? p->layered_friction_value : p->element.friction;
    CDEM_TRY(check_value("heterogeneity", "layered_friction_value", lf, 0, err));
    const cdem_contact_material *e = &p->element;
    law->friction[CDEM_CLASS_WEAK] = e->friction * ws;
    law->cohesion[CDEM_CLASS_WEAK] = e->cohesion * ws;
    law->breaking_strain[CDEM_CLASS_WEAK] = e->breaking_strain * ws;
    law->friction[CDEM_CLASS_LAYERED] = lf;
    law->cohesion[CDEM_CLASS_LAYERED] = e->cohesion;
    law->breaking_strain[CDEM_CLASS_LAYERED] = e->breaking_strain;
    law->friction[CDEM_CLASS_LAYERED_WEAK] = lf * ws;
    law->cohesion[CDEM_CLASS_LAYERED_WEAK] = e->cohesion * ws;
    law->breaking_strain[CDEM_CLASS_LAYERED_WEAK] = e->breaking_strain * ws;
    law->friction[CDEM_CLASS_SLIP] = 0.0;
    law->cohesion[CDEM_CLASS_SLIP] = 0.0;
    law->breaking_strain[CDEM_CLASS_SLIP] = 0.0;
    return CDEM_OK;
}

int cdem_contact_layered_layer(int32_t layer) {
    return layer >= 1 && layer <= CDEM_PREGROWTH_LAYERS && ((layer - 1) / 4) % 2 == 1;
}

int cdem_contact_weak_layer(int32_t layer) {
    return layer >= 4 && layer <= 20 && layer % 4 == 0;
}

int cdem_contact_refine(const cdem_contact_law *law, int cls, int32_t layer_i, uint32_t flags_i,
                        int32_t layer_j, uint32_t flags_j) {
    if (cls != CDEM_CLASS_ELEMENT)
        return cls;
    if (law->flexural_slip && layer_i >= 1 && layer_i <= CDEM_PREGROWTH_LAYERS && layer_j >= 1 &&
        layer_j <= CDEM_PREGROWTH_LAYERS &&
        (law->flexural_slip == 1
             ? layer_i != layer_j
             : cdem_contact_weak_layer(layer_i) || cdem_contact_weak_layer(layer_j)))
        return CDEM_CLASS_SLIP;
    const int weak = ((flags_i | flags_j) & CDEM_FLAG_WEAK) != 0;
    const int layered = law->layered_friction && (cdem_contact_layered_layer(layer_i) ||
                                                  cdem_contact_layered_layer(layer_j));
    static const int table[2][2] = {{CDEM_CLASS_ELEMENT, CDEM_CLASS_WEAK},
                                    {CDEM_CLASS_LAYERED, CDEM_CLASS_LAYERED_WEAK}};
    return table[layered][weak];
}

cdem_status cdem_contact_assign_weak(const cdem_params *p, cdem_state *s, long *marked,
                                     cdem_error *err) {
    if (marked)
        *marked = 0;
    if (!p || !s)
        return CDEM_FAIL(err, CDEM_ERR_INVALID, "cdem_contact_assign_weak: NULL argument");
    if (p->weak_interval == CDEM_WEAK_OFF)
        return CDEM_OK;
    if (p->weak_interval != CDEM_WEAK_LOWER && p->weak_interval != CDEM_WEAK_UPPER)
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "heterogeneity.weak_interval = %d: must be off, lower or upper",
                         (int)p->weak_interval);
    if (!(p->weak_thickness_percent >= 0.0 && p->weak_thickness_percent <= 100.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "heterogeneity.weak_thickness_percent = %g: must be 0..100",
                         p->weak_thickness_percent);
    if (!(p->weak_density_percent > 0.0 && p->weak_density_percent <= 100.0))
        return CDEM_FAIL(err, CDEM_ERR_RANGE,
                         "heterogeneity.weak_density_percent = %g: must be > 0 and <= 100",
                         p->weak_density_percent);
    double lo, hi;
    cdem_state_free_y_range(s, &lo, &hi);
    if (!(hi >= lo))
        return CDEM_OK; /* no free elements */
    const double th = p->weak_thickness_percent / 100.0 * (hi - lo);
    const double fd = p->weak_density_percent / 100.0;
    long count = 0;
    for (size_t i = 0; i < s->n; i++) {
        if (s->flags[i] & (CDEM_FLAGS_BOUNDARY | CDEM_FLAG_WEAK))
            continue;
        const int in =
            p->weak_interval == CDEM_WEAK_LOWER ? s->y[i] <= lo + th : s->y[i] >= hi - th;
        if (!in || th <= 0.0)
            continue;
        s->flags[i] |= CDEM_FLAG_WEAK;
        s->mass[i] *= fd;
        count++;
    }
    if (marked)
        *marked = count;
    return CDEM_OK;
}

/* ---------------------------------------------------------------- checkpoints */

/* The law as a flat array of doubles, in a fixed order (the check compares bits). */
static size_t law_values(const cdem_contact_law *law, double *v) {
    size_t k = 0;
    v[k++] = (double)law->model;
    v[k++] = (double)law->first_slip;
    v[k++] = law->kn;
    v[k++] = law->ks;
    for (int c = 0; c < CDEM_CLASS_TOTAL; c++) {
        v[k++] = law->friction[c];
        v[k++] = law->cohesion[c];
        v[k++] = law->breaking_strain[c];
    }
    v[k++] = law->max_breaking_strain;
    v[k++] = (double)law->flexural_slip;
    v[k++] = (double)law->layered_friction;
    v[k++] = (double)law->granular;
    v[k++] = (double)law->cohesive_rule;
    v[k++] = law->settling_friction;
    /* the law's coefficients, only when it has some (a checkpoint of a law without stays as
     * it was) */
    for (int c = 0; c < law->coefficient_count; c++)
        v[k++] = law->coef[c];
    return k;
}

#define LAW_VALUES (4 + 3 * CDEM_CLASS_TOTAL + 6 + CDEM_LAW_MAX_COEFFICIENTS)

cdem_status cdem_contact_snapshot_put(const cdem_contact_law *law, cdem_snapshot *snap,
                                      cdem_error *err) {
    double v[LAW_VALUES];
    const size_t n = law_values(law, v);
    return cdem_ckpt_put_array(snap, "contact", "law", CDEM_SNAP_F64, n, v, err);
}

cdem_status cdem_contact_snapshot_check(const cdem_contact_law *law, const cdem_snapshot *snap,
                                        cdem_error *err) {
    double v[LAW_VALUES];
    const size_t n = law_values(law, v);
    const cdem_snapshot_array *a = NULL;
    CDEM_TRY(cdem_ckpt_get_array(snap, "contact", "law", CDEM_SNAP_F64, SIZE_MAX, &a, err));
    const double *stored = a->data;
    for (size_t k = 0; k < n && k < a->count; k++)
        if (memcmp(&stored[k], &v[k], sizeof v[k]) != 0)
            return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                             "checkpoint contact.law value %zu = %.17g but this run's contact law "
                             "has %.17g: the checkpoint belongs to another material",
                             k, stored[k], v[k]);
    if (a->count != n) /* the same values, but for the law's coefficients */
        return CDEM_FAIL(err, CDEM_ERR_CONFLICT,
                         "checkpoint contact.law has %zu values but this run's contact law has "
                         "%zu (%d coefficients of its own): the checkpoint belongs to another "
                         "material",
                         a->count, n, law->coefficient_count);
    return CDEM_OK;
}
