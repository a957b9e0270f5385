/* contact: the pair force laws of SPEC section 4 (bonded and frictional-cohesive), evaluated
 * for one pair with its history. Every contact law implements the same checklist:
 *   - eval: force on the first element of the pair from (separation vector, sum of radii,
 *     relative velocity, dt) and the pair's history (tangential displacement, flags);
 *   - state change rules: when cohesion/bond is created (cdem_contact_make_cohesive, called
 *     by the run loop at the end of equilibration), lost (slip, separation) or broken.
 * The law is a plain value (cdem_contact_law) built once from params + model; the pair
 * history is owned by the pair list (neighbour.h), keyed by the element ids, so it survives
 * list rebuilds, re-sorting and element removal. Evaluation is a static inline function:
 * pure, thread-safe for distinct pairs (one writer per pair slot).
 * Sign convention: n = (xj - xi)/r, t = (-ny, nx); the returned force acts on i (j gets
 * minus it). Normal force on i = Kn (r - R) n (negative along n = repulsion when r < R).
 * Tangential: Xs += ((vj - vi) . t) dt; force on i = +Ks Xs t (the spring drags i along j).
 * The scalar Xs lives in the contact frame, so it rotates with the pair automatically.
 * Units: m, m/s, s, N (per metre of thickness). */
#ifndef CDEM_CONTACT_H
#define CDEM_CONTACT_H

#include "cdem_error.h"
#include "params.h"

#include <math.h>
#include <stdint.h>

/* Contact classes: which material values a pair uses. */
enum {
    CDEM_CLASS_ELEMENT = 0, /* element-element: params.element */
    CDEM_CLASS_WALL = 1,    /* element-wall (either flagged CDEM_FLAG_WALL): params.wall */
    CDEM_CLASS_FAULT = 2,   /* element-fault (either flagged CDEM_FLAG_FAULT): params.fault */
    CDEM_CLASS_COUNT = 3
};

/* Pair history flags (uint8 per pair). */
enum {
    CDEM_PAIR_TOUCH = 1u << 0,    /* r < R at the last evaluation (a contact) */
    CDEM_PAIR_COHESIVE = 1u << 1, /* granular: the Coulomb limit includes the cohesion C0 */
    CDEM_PAIR_BONDED = 1u << 2,   /* bonded model: the bond is intact (tension allowed) */
};

typedef struct {
    cdem_material_model model;         /* granular or bonded */
    int first_slip;                    /* 1: cohesion lost at the first slip; 0: at separation */
    double kn;                         /* N/m, normal spring stiffness, > 0 */
    double ks;                         /* N/m, shear spring stiffness, >= 0 */
    double friction[CDEM_CLASS_COUNT]; /* Coulomb coefficient mu per class, >= 0 */
    double cohesion[CDEM_CLASS_COUNT]; /* C0 per class, N, >= 0 */
    double breaking_strain[CDEM_CLASS_COUNT]; /* r0 per class (bonded), > 0 */
    double max_breaking_strain; /* largest r0 of the classes when bonded, else 0 (cut-off) */
} cdem_contact_law;

/* Fills the law from the material parameters and the model constants kn, ks. Fails with
 * CDEM_ERR_RANGE naming the field when a value is negative/non-finite or kn <= 0. */
cdem_status cdem_contact_law_init(cdem_contact_law *law, const cdem_params *p, double kn, double ks,
                                  cdem_error *err);

/* Name of a class for messages and views ("element", "wall", "fault"). */
const char *cdem_contact_class_name(int cls);

/* Class of a pair from the two elements' flags (CDEM_FLAG_*): fault beats wall beats
 * element. Returns -1 when the pair never interacts (both boundary elements, or either a
 * display-only footwall element). */
int cdem_contact_class(uint32_t flags_i, uint32_t flags_j);

/* Evaluates one pair. dx, dy = xj - xi; R = ri + rj; dvx, dvy = vj - vi (mid-step velocities,
 * so dv * dt is the relative displacement of the step). Updates *xs and *hist; writes the
 * force on i. Cost: no sqrt unless the pair is within reach (touching or a bond). */
static inline void cdem_contact_eval(const cdem_contact_law *law, int cls, double dx, double dy,
                                     double R, double dvx, double dvy, double dt, double *xs,
                                     uint8_t *hist, double *fx, double *fy) {
    const double r2 = dx * dx + dy * dy;
    uint8_t h = *hist;
    if (h & CDEM_PAIR_BONDED) {
        /* Bonded model, intact bond: linear spring in tension and compression until
         * r - R >= r0 R, then broken for good (still repulsive below R). */
        const double r = sqrt(r2);
        const double reach = law->breaking_strain[cls] * R;
        if (r - R >= reach) {
            h &= (uint8_t)~CDEM_PAIR_BONDED;
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
        *hist = (uint8_t)(h & CDEM_PAIR_BONDED); /* bonded flag already cleared above */
        return;
    }
    const double r = sqrt(r2);
    const double inv = 1.0 / r;
    const double nx = dx * inv, ny = dy * inv;
    const double fn = law->kn * (R - r); /* compressive normal force magnitude, > 0 */
    double ftx = 0.0, fty = 0.0;
    h |= CDEM_PAIR_TOUCH;
    if (law->model == CDEM_MATERIAL_GRANULAR && law->ks > 0.0) {
        const double tx = -ny, ty = nx;
        double s = *xs + (dvx * tx + dvy * ty) * dt;
        double fs = law->ks * s;
        double limit = law->friction[cls] * fn;
        if (h & CDEM_PAIR_COHESIVE)
            limit += law->cohesion[cls];
        if (fabs(fs) > limit) {
            /* Slip: scale the spring back to the strength. */
            fs = fs > 0.0 ? limit : -limit;
            s = fs / law->ks;
            if (law->first_slip)
                h &= (uint8_t)~CDEM_PAIR_COHESIVE;
        }
        *xs = s;
        ftx = fs * tx;
        fty = fs * ty;
    }
    *fx = -fn * nx + ftx;
    *fy = -fn * ny + fty;
    *hist = h;
}

#endif
