/* contact: the pair force laws of the manual and paper (bonded and frictional-cohesive), evaluated
 * for one pair with its history, in one kernel (cdem_contact_touching / cdem_contact_eval)
 * that the integrator's force loop, the tests and everything else call. The granular laws
 * differ only in how the cohesion C0 enters the shear strength; each is a file of
 * common/laws/ and a line of laws.def (the interface in law.h), selected by
 * material.granular_law. State change rules, the same for every law:
 *   - cohesion/bond created: at the end of equilibration for every touching pair
 *     (cdem_integrator_make_cohesive); with cohesive_contacts = formed also for every
 *     contact that forms afterwards (cdem_contact_law_phase sets cohesive_new); with
 *     cohesive_contacts = initial only for the touching pairs that were contacts of the
 *     built assembly and never separated (CDEM_PAIR_INITIAL, set by
 *     cdem_integrator_mark_initial before the first step);
 *   - lost: at the first slip (first_slip on) or when the pair separates;
 *   - the packing phase: while equilibrating, friction x settling_friction
 *     (cdem_contact_law_phase; the run loop says which phase a step is in).
 * The law is a plain value (cdem_contact_law) built once from params + model, with the
 * granular law's own coefficients (coef, filled by the law's setup from its CDEM_LAW_STATE
 * row, law.h); the pair history (flags, Xs and the law's history slots, law->slot_count
 * doubles per pair) is owned by the pair list (neighbour.h), keyed by the element ids, so it
 * survives list rebuilds, re-sorting and element removal. Separation ends a contact: its Xs
 * and its slots go back to 0 (cdem_contact_forget_slots). Evaluation is inline and pure,
 * thread-safe for distinct pairs (one writer per pair slot).
 * Sign convention: n = (xj - xi)/r, t = (-ny, nx); the returned force acts on i (j gets
 * minus it). Normal force on i = Kn (r - R) n (negative along n = repulsion when r < R).
 * Tangential: Xs += ((vj - vi) . t) dt; force on i = +Fs t, Fs from the law (the spring
 * drags i along j). The scalar Xs lives in the contact frame, so it rotates with the pair.
 * Classes: element, wall, base (the base row: material.base_*, by default the wall's
 * values), fault; element-element pairs are refined at each list rebuild into heterogeneity
 * classes (weak, layered, layered+weak, flexural slip) by cdem_contact_refine from the two
 * elements' layers and CDEM_FLAG_WEAK; the hot loop only indexes the per-class arrays.
 * Units: m, m/s, s, N (per metre of thickness). */
#ifndef CDEM_CONTACT_H
#define CDEM_CONTACT_H

#include "cdem_error.h"
#include "params.h"
#include "snapshot.h"
#include "state.h"

/* the laws' scalar kernels (common/laws/law.h) */
#define CDEM_LAW_SCALAR
#include "laws/law.h"
#include "laws/laws.def"

#include <math.h>
#include <stdint.h>

/* Contact classes: which material values a pair uses. */
enum {
    CDEM_CLASS_ELEMENT = 0, /* element-element: params.element */
    CDEM_CLASS_WALL = 1,    /* element-wall (either flagged CDEM_FLAG_WALL): params.wall */
    CDEM_CLASS_FAULT = 2,   /* element-fault (either flagged CDEM_FLAG_FAULT): params.fault */
    CDEM_CLASS_BASE = 3,    /* element-base (a wall flagged CDEM_FLAG_BASE): params.base */
    CDEM_CLASS_COUNT = 4,   /* number of base classes (element, wall, fault, base) */
    /* element-element refinements (heterogeneity), chosen by cdem_contact_refine */
    CDEM_CLASS_WEAK = 4,         /* either element weak: element values x weak_strength_percent */
    CDEM_CLASS_LAYERED = 5,      /* either element in layers 5-8/13-16/21-24: layered friction */
    CDEM_CLASS_LAYERED_WEAK = 6, /* both rules: layered friction x weak_strength_percent */
    CDEM_CLASS_SLIP = 7,         /* flexural slip: different pre-growth layers, no strength */
    CDEM_CLASS_TOTAL = 8         /* length of the per-class arrays */
};

/* Pair history flags (uint8 per pair). */
enum {
    CDEM_PAIR_TOUCH = 1u << 0,    /* r < R at the last evaluation (a contact) */
    CDEM_PAIR_COHESIVE = 1u << 1, /* granular: the Coulomb limit includes the cohesion C0 */
    CDEM_PAIR_BONDED = 1u << 2,   /* bonded model: the bond is intact (tension allowed) */
    CDEM_PAIR_INITIAL = 1u << 3,  /* a contact of the built assembly that has not separated
                                     (cohesive_contacts = initial; until equilibration ends) */
};

typedef struct {
    cdem_material_model model;            /* granular or bonded */
    int first_slip;                       /* 1: cohesion lost at the first slip; 0: at separation */
    cdem_granular_law granular;           /* granular: how C0 enters the strength (law_*.h) */
    cdem_cohesive_contacts cohesive_rule; /* granular: which contacts carry C0 */
    double settling_friction;             /* friction multiplier while equilibrating, 0..1 */
    int cohesive_new;                  /* 1 on the steps where a forming contact is cohesive (set by
                                          cdem_contact_law_phase from cohesive_rule; 0 in the material) */
    double kn;                         /* N/m, normal spring stiffness, > 0 */
    double ks;                         /* N/m, shear spring stiffness, >= 0 */
    double friction[CDEM_CLASS_TOTAL]; /* Coulomb coefficient mu per class, >= 0 */
    double cohesion[CDEM_CLASS_TOTAL]; /* C0 per class, N, >= 0 */
    double breaking_strain[CDEM_CLASS_TOTAL]; /* r0 per class (bonded), > 0 (0 for SLIP) */
    double max_breaking_strain; /* largest r0 of the classes when bonded, else 0 (cut-off) */
    int flexural_slip;          /* 0 off; 1: pairs of different pre-growth layers use
                                   CDEM_CLASS_SLIP; 2: pairs with an element of a weak layer
                                   (cdem_contact_weak_layer) do */
    int layered_friction;       /* 0/1: layers 5-8, 13-16, 21-24 use CDEM_CLASS_LAYERED */
    /* the granular law's own (its CDEM_LAW_STATE row, law.h; 0 and 0 when it has none, and
       for the bonded model) */
    int coefficient_count;                  /* coef[0..coefficient_count-1] are its */
    int slot_count;                         /* history slots per pair (the pair list's) */
    double coef[CDEM_LAW_MAX_COEFFICIENTS]; /* filled once by the law's setup */
} cdem_contact_law;

/* Fills the law from the material parameters and the model constants kn, ks, and the
 * granular law's coefficients by its setup (law.h). Fails with CDEM_ERR_RANGE naming the field
 * when a value is negative/non-finite or kn <= 0, or as the law's setup fails. */
cdem_status cdem_contact_law_init(cdem_contact_law *law, const cdem_params *p, double kn, double ks,
                                  cdem_error *err);

/* Name of a class for messages and views ("element", "wall", "fault"). */
const char *cdem_contact_class_name(int cls);

/* Class of a pair from the two elements' flags (CDEM_FLAG_*): fault beats wall (base for a
 * wall flagged CDEM_FLAG_BASE) beats element. Returns -1 when the pair is not one of the pair
 * list's: it never interacts (both boundary elements, or either a display-only footwall
 * element) or it has a process's element (CDEM_FLAGS_PROCESS: the process evaluates it). */
int cdem_contact_class(uint32_t flags_i, uint32_t flags_j);

/* Refines a base class (cdem_contact_class) of a pair from its elements' layers and flags.
 * Only CDEM_CLASS_ELEMENT is refined (walls and faults keep their own materials). Rules,
 * in order: flexural slip on, both layers in 1..24 and, by style, different (layer
 * contacts) or one of them a weak layer (weak layers) -> SLIP (no strength, no bond); else weak =
 * either element has CDEM_FLAG_WEAK, layered = layered friction on and either layer in 5-8, 13-16
 * or 21-24 -> ELEMENT, WEAK, LAYERED or LAYERED_WEAK. */
int cdem_contact_refine(const cdem_contact_law *law, int cls, int32_t layer_i, uint32_t flags_i,
                        int32_t layer_j, uint32_t flags_j);

/* 1 when pre-growth layer L (1..24) is one of the layered-friction layers 5-8, 13-16,
 * 21-24; 0 otherwise (growth layers 25.. and walls 0 never are). */
int cdem_contact_layered_layer(int32_t layer);

/* 1 when pre-growth layer L is one of flexural slip's weak layers 4, 8, 12, 16, 20 (style
 * weak-layers, the original program's versions 4.1-4.2); 0 otherwise. */
int cdem_contact_weak_layer(int32_t layer);

/* Weak/light interval at assembly time (before equilibration, so the equilibrated state
 * carries the density): among free elements, those whose centre lies in the lowest
 * (CDEM_WEAK_LOWER) or highest (CDEM_WEAK_UPPER) weak_thickness_percent of the span of
 * free-element centres get CDEM_FLAG_WEAK and mass x weak_density_percent/100. Does
 * nothing when weak_interval is off. *marked (may be NULL) receives the count. Fails with
 * CDEM_ERR_RANGE naming the key when a percentage is outside 0..100. */
cdem_status cdem_contact_assign_weak(const cdem_params *p, cdem_state *s, long *marked,
                                     cdem_error *err);

/* Checkpoints (checkpoint.h): the law's values under "contact." (model, first_slip, kn, ks,
 * per-class friction, cohesion, breaking strain, heterogeneity switches, and after them the
 * granular law's coefficients when it has any: a law without is stored as it always was).
 * The contact histories themselves (flags, tangential displacement, the law's slots) belong
 * to the pair list and are stored with it (cdem_neighbour_snapshot_put). _check fails with
 * CDEM_ERR_CONFLICT naming the value when the law of the run being resumed differs from the
 * stored one. */
cdem_status cdem_contact_snapshot_put(const cdem_contact_law *law, cdem_snapshot *snap,
                                      cdem_error *err);
cdem_status cdem_contact_snapshot_check(const cdem_contact_law *law, const cdem_snapshot *snap,
                                        cdem_error *err);

/* The law in force on one step (the integrator copies it for every force pass):
 * equilibrating = 1 (the packing phase, steps 1..equilibration): every class's friction
 * times settling_friction, and no contact becomes cohesive as it forms; otherwise the
 * material as given, and with cohesive_contacts = formed every contact that forms is
 * cohesive from its first step. Pure. */
static inline void cdem_contact_law_phase(const cdem_contact_law *law, int equilibrating,
                                          cdem_contact_law *out) {
    *out = *law;
    out->cohesive_new = !equilibrating && law->cohesive_rule == CDEM_COHESIVE_FORMED;
    if (equilibrating && law->settling_friction != 1.0)
        for (int c = 0; c < CDEM_CLASS_TOTAL; c++)
            out->friction[c] = law->friction[c] * law->settling_friction;
}

/* Relative reach of an initial contact (CDEM_PAIR_INITIAL): the built assembly's contacts are
 * exact tangencies up to round-off, so a pair of them counts as not separated while
 * r < R (1 + 1e-9), squared here. */
#define CDEM_INITIAL_REACH2 (1.0 + 2e-9)

/* The history a separated pair keeps (r >= R): nothing, except the mark of an initial
 * contact that is still within CDEM_INITIAL_REACH2 (an exact tangency of the built
 * assembly). */
static CDEM_INLINE uint8_t cdem_contact_separated(uint8_t h, double r2, double R) {
    return (uint8_t)((h & CDEM_PAIR_INITIAL) && r2 > 0.0 && r2 < R * R * CDEM_INITIAL_REACH2
                         ? CDEM_PAIR_INITIAL
                         : 0);
}

/* A separated pair's history slots (law->slot_count at slots) go back to 0, with its Xs: the
 * next contact of the pair is a new one (law.h). */
static CDEM_INLINE void cdem_contact_forget_slots(const cdem_contact_law *law, double *slots) {
    for (int k = 0; k < law->slot_count; k++)
        slots[k] = 0.0;
}

/* cdem_contact_touching; stateful: a constant, 0 only in the force pass's loops of the laws
 * without state (law.h, CDEM_LAW_CALL: the laws with state are not compiled into them). */
static CDEM_INLINE void cdem_contact_touching_of(const cdem_contact_law *law, int cls, double r2,
                                                 double dx, double dy, double R, double dvx,
                                                 double dvy, double dt, double *xs, uint8_t *hist,
                                                 double *slots, double *fx, double *fy,
                                                 int stateful) {
    uint8_t h = *hist;
    const double r = sqrt(r2);
    const double inv = 1.0 / r;
    const double nx = dx * inv, ny = dy * inv;
    const double fn = law->kn * (R - r); /* compressive normal force magnitude, > 0 */
    double ftx = 0.0, fty = 0.0;
    if (!(h & CDEM_PAIR_TOUCH) && law->cohesive_new)
        h |= CDEM_PAIR_COHESIVE; /* a contact forming now (cohesive_contacts = formed) */
    h |= CDEM_PAIR_TOUCH;
    if (law->model == CDEM_MATERIAL_GRANULAR && law->ks > 0.0) {
        const double tx = -ny, ty = nx;
        double sv = *xs + (dvx * tx + dvy * ty) * dt;
        const double spring = law->ks * sv;
        const double mu = law->friction[cls];
        const double c0 = (h & CDEM_PAIR_COHESIVE) ? law->cohesion[cls] : 0.0;
        cdem_shear sh = {0.0, 0.0, 0};
        switch (law->granular) { /* one case per row of laws.def */
#define CDEM_LAW(ID, word, description, scalar, lanes)                                             \
    case CDEM_LAW_##ID:                                                                            \
        sh = CDEM_LAW_CALL(scalar, spring, fn, mu, c0, law->coef, slots, stateful);                \
        break;
#define CDEM_TEST_LAW CDEM_LAW
#include "laws/laws.def"
#undef CDEM_LAW
#undef CDEM_TEST_LAW
        default: /* none: cdem_contact_law_init refuses any value without a row */
            break;
        }
        if (sh.slid) {
            sv = sh.spring / law->ks;
            if (law->first_slip)
                h &= (uint8_t)~CDEM_PAIR_COHESIVE;
        }
        *xs = sv;
        ftx = sh.force * tx;
        fty = sh.force * ty;
    }
    *fx = -fn * nx + ftx;
    *fy = -fn * ny + fty;
    *hist = h;
}

/* A touching pair (0 < r2 < R^2) that is not an intact bond: repulsive normal force and,
 * for the granular material, the tangential spring limited by the pair's law. The one
 * kernel of the granular laws: the integrator, the tests and everything else call it (or
 * cdem_contact_eval, which ends here). Arguments as cdem_contact_eval's; r2 = dx^2 + dy^2. */
static CDEM_INLINE void cdem_contact_touching(const cdem_contact_law *law, int cls, double r2,
                                              double dx, double dy, double R, double dvx,
                                              double dvy, double dt, double *xs, uint8_t *hist,
                                              double *slots, double *fx, double *fy) {
    cdem_contact_touching_of(law, cls, r2, dx, dy, R, dvx, dvy, dt, xs, hist, slots, fx, fy, 1);
}

/* Evaluates one pair. dx, dy = xj - xi; R = ri + rj; dvx, dvy = vj - vi (mid-step velocities,
 * so dv * dt is the relative displacement of the step). Updates *xs, *hist and the pair's
 * history slots (law->slot_count of them at slots; may be NULL when the law has none); writes
 * the force on i. Cost: no sqrt unless the pair is within reach (touching or a bond). */
static inline void cdem_contact_eval(const cdem_contact_law *law, int cls, double dx, double dy,
                                     double R, double dvx, double dvy, double dt, double *xs,
                                     uint8_t *hist, double *slots, double *fx, double *fy) {
    const double r2 = dx * dx + dy * dy;
    uint8_t h = *hist;
    if (h & CDEM_PAIR_BONDED) {
        /* Bonded model, intact bond: linear spring in tension and compression until
         * r - R >= r0 R, then broken for good (still repulsive below R). */
        const double r = sqrt(r2);
        const double reach = law->breaking_strain[cls] * R;
        if (r - R >= reach) {
            h &= (uint8_t)~CDEM_PAIR_BONDED;
            *hist = h;
        } else {
            const double f = law->kn * (r - R) / r;
            *fx = f * dx;
            *fy = f * dy;
            *hist = (uint8_t)(r < R ? (h | CDEM_PAIR_TOUCH) : (h & ~CDEM_PAIR_TOUCH));
            return;
        }
    }
    if (r2 >= R * R || r2 <= 0.0) {
        /* Separated: all forces zero; granular history (Xs, cohesion) deleted. A coincident
         * pair (r = 0) has no direction and is treated as separated. */
        *fx = 0.0;
        *fy = 0.0;
        *xs = 0.0;
        cdem_contact_forget_slots(law, slots);
        *hist = cdem_contact_separated(h, r2, R); /* a broken bond never comes back */
        return;
    }
    cdem_contact_touching(law, cls, r2, dx, dy, R, dvx, dvy, dt, xs, hist, slots, fx, fy);
}

#endif
