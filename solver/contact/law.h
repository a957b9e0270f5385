/* law: what every granular contact law returns. A law (solver/law_<name>.h, one static
 * inline function each) turns the trial elastic shear force of a touching contact,
 * spring = Ks Xs with Xs already advanced by this step's tangential displacement, the
 * compressive normal force fn (N, >= 0), the friction coefficient mu and the cohesion c0 of
 * the contact (N; 0 when the contact is not cohesive) into
 *   force  - the tangential force the contact transmits (N, signed along t),
 *   spring - the elastic shear force to keep (the kernel stores Xs = spring / Ks),
 *   slid   - 1 when the trial force exceeded the Coulomb threshold (a slip: cohesion is
 *            lost here when first_slip is on).
 * The shared kernel (contact.h, cdem_contact_eval) does everything else (normal force,
 * separation, cohesion bookkeeping), so adding a law is one new file, one enum value
 * (common/params.h) and one row in the registry (contact.c). */
#ifndef CDEM_LAW_H
#define CDEM_LAW_H

/* The per-pair kernel and the laws are inlined into the force loop whatever the compiler's
 * inlining budget says (a call per touching pair cost about 4 % of a step). */
#if defined(__GNUC__)
#define CDEM_INLINE inline __attribute__((always_inline))
#else
#define CDEM_INLINE inline
#endif

typedef struct {
    double force;  /* N, tangential force on the contact */
    double spring; /* N, elastic shear force kept for the next step (Ks Xs) */
    int slid;      /* 1: the contact slid this step */
} cdem_shear;

#endif
