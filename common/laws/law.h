/* law: what a granular contact law is. A law turns the trial elastic shear force of a
 * touching contact, spring = Ks Xs with Xs already advanced by this step's tangential
 * displacement, the compressive normal force fn (N, >= 0), the friction coefficient mu and the
 * cohesion c0 of the contact (N; 0 when the contact is not cohesive) into
 *   force  - the tangential force the contact transmits (N, signed along t),
 *   spring - the elastic shear force to keep (the kernel stores Xs = spring / Ks),
 *   slid   - 1 when the trial force exceeded the law's limit (a slip: cohesion is lost here
 *            when first_slip is on).
 * The shared kernel (solver/contact/contact.h) does everything else: normal force,
 * separation, cohesion bookkeeping.
 * A law may have coefficients of its own (numbers read once from the parameters, the same for
 * every contact: coef[0..coefficients-1]) and a history of its own per contact (slots[0..
 * slots-1], doubles that persist from step to step, as LAMMPS's granular sub-models declare
 * num_coeffs and size_history). The machinery carries the slots as it carries Xs: the pair
 * list keeps them across list rebuilds, re-sorting and element removal, and a checkpoint
 * stores them. A contact's slots are its own: 0 when the pair enters the list, set back to
 * 0 with Xs when the pair separates, so a new contact of the pair starts from 0. A law has
 * no memory of separated contacts: one that outlived the contact would last only while the
 * pair stays in the list, i.e. it would depend on the list's skin.
 * A law is one file, common/laws/law_<name>.h, listed by one line in laws.def. The file has
 * up to six parts, each compiled only where it is asked for:
 *   CDEM_LAW_SCALAR  its scalar kernel (the contact kernel of both force paths), in one of
 *                    two forms: cdem_law_<name>(spring, fn, mu, c0) -> cdem_shear for a law
 *                    without coefficients or slots, or cdem_law_<name>(spring, fn, mu, c0,
 *                    const double *coef, double *slots) -> cdem_shear (slots: this
 *                    contact's, written in place). The kernel's type says which
 *                    (CDEM_LAW_CALL), so a law of the short form compiles to what it always
 *                    did;
 *   CDEM_LAW_LANES   its AVX2 kernel, the same operations on four contacts in the lanes of
 *                    __m256d -> cdem_shear4 (solver/step/force_avx2.c), or none: a law without
 *                    one is evaluated by its scalar kernel on the vector path too. A law with
 *                    coefficients or slots has none (tests/test_registry_solver.c checks);
 *   CDEM_LAW         its row CDEM_LAW(ID, word, description, scalar kernel, AVX2 kernel or
 *                    NULL), from which the enum (params.h), the parameter words and help
 *                    (params.c), the summary line and both kernels' dispatch are made;
 *   CDEM_LAW_STATE   its row CDEM_LAW_STATE(ID, coefficients, slots, setup): how many
 *                    coefficients (at most CDEM_LAW_MAX_COEFFICIENTS) and history slots per
 *                    contact it has, and the function that fills coef from the parameters,
 *                    cdem_status setup(const cdem_params *p, double *coef, cdem_error *err)
 *                    (NULL without coefficients), which cdem_contact_law_init calls once. A
 *                    law without this row has none of either;
 *   CDEM_LAW_SETUP   that setup function (compiled in solver/contact/contact.c, where
 *                    cdem_params and the error helpers are known);
 *   CDEM_PARAM_*     the parameters its coefficients come from, if it has any: its fields of
 *                    cdem_params and its rows of the table, in [material] (common/params.h
 *                    says how these parts are gathered; a fixture's rows are marked so).
 * A law without coefficients or slots is its kernels and its row CDEM_LAW; one with them adds
 * the rest, and nothing outside its file changes (law_test_slip_weakening.h is the proof).
 * A fixture of the tests writes CDEM_TEST_LAW instead of CDEM_LAW: it is registered (the
 * kernels, the enum after the users' laws) but no parameter file can name it.
 * The laws live in common/ because both programs read their words (the analysis reads the
 * parameters stored in a run file); only cdem-run evaluates them.
 * Pure functions (a kernel with slots writes only its contact's); units N. */
#ifndef CDEM_LAW_H
#define CDEM_LAW_H

#include <math.h>

/* The per-pair kernel and the laws are inlined into the force loop whatever the compiler's
 * inlining budget says (a call per touching pair is a measurable part of a step). */
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

/* The end of every law so far: the trial force f transmitted while |f| <= limit, else the
 * limit with f's sign, which is then also the spring kept (a slip; unloading starts from
 * the limit). spring is the elastic force kept when there is no slip. */
static CDEM_INLINE cdem_shear cdem_law_cap(double f, double spring, double limit) {
    cdem_shear s = {f, spring, 0};
    if (fabs(f) > limit) {
        s.force = f > 0.0 ? limit : -limit;
        s.spring = s.force;
        s.slid = 1;
    }
    return s;
}

/* The most coefficients a law may declare (the room in cdem_contact_law). */
#define CDEM_LAW_MAX_COEFFICIENTS 8

/* The two forms of a scalar kernel (see above). */
typedef cdem_shear cdem_law_kernel(double spring, double fn, double mu, double c0);
typedef cdem_shear cdem_law_kernel_with_state(double spring, double fn, double mu, double c0,
                                              const double *coef, double *slots);

static CDEM_INLINE cdem_shear cdem_law_call_plain(cdem_law_kernel *kernel, double spring, double fn,
                                                  double mu, double c0, const double *coef,
                                                  double *slots, int stateful) {
    (void)coef;
    (void)slots;
    (void)stateful;
    return kernel(spring, fn, mu, c0);
}

static CDEM_INLINE cdem_shear cdem_law_call_with_state(cdem_law_kernel_with_state *kernel,
                                                       double spring, double fn, double mu,
                                                       double c0, const double *coef, double *slots,
                                                       int stateful) {
    if (!stateful) /* never: see CDEM_LAW_CALL */
        __builtin_unreachable();
    return kernel(spring, fn, mu, c0, coef, slots);
}

/* Calls a law's scalar kernel in its form, chosen by the kernel's type at compile time (a
 * kernel of neither form does not compile): a kernel with state gets coef and the contact's
 * slots. Inlined, so a kernel of the short form runs exactly as when it was called directly:
 * nothing reads the other arguments, so the compiler computes none of them. stateful is a
 * constant of the caller: 0 in the force pass's loops of the laws without state, where the
 * cases of the laws with state are then unreachable and compiled away (they run in a loop
 * of their own), so that these loops are the same instructions as before any law had state;
 * 1 everywhere else. */
/* clang-format off */
#define CDEM_LAW_CALL(kernel, spring, fn, mu, c0, coef, slots, stateful)                           \
    _Generic(&(kernel),                                                                            \
             cdem_law_kernel *: cdem_law_call_plain,                                               \
             cdem_law_kernel_with_state *: cdem_law_call_with_state)                               \
        (kernel, spring, fn, mu, c0, coef, slots, stateful)
/* clang-format on */

#endif

/* The lanes' types, when a file asks for the AVX2 kernels (x86-64 with GCC or clang only). */
#if defined(CDEM_LAW_LANES) && !defined(CDEM_LAW_LANES_H)
#define CDEM_LAW_LANES_H

#include <immintrin.h>

#define CDEM_LANES static inline __attribute__((always_inline, target("avx2")))

typedef struct {
    __m256d force;  /* N per lane, as cdem_shear */
    __m256d spring; /* N per lane */
    __m256d slid;   /* all bits set in a lane that slid, else 0 (a blend mask) */
} cdem_shear4;

/* cdem_law_cap on four lanes: the same comparisons, with masks where it branches. */
CDEM_LANES cdem_shear4 cdem_law_cap4(__m256d f, __m256d spring, __m256d limit) {
    const __m256d zero = _mm256_setzero_pd(), sign = _mm256_set1_pd(-0.0);
    const __m256d slid = _mm256_cmp_pd(_mm256_andnot_pd(sign, f), limit, _CMP_GT_OQ);
    const __m256d capped =
        _mm256_blendv_pd(_mm256_xor_pd(limit, sign), limit, _mm256_cmp_pd(f, zero, _CMP_GT_OQ));
    const __m256d force = _mm256_blendv_pd(f, capped, slid);
    return (cdem_shear4){force, _mm256_blendv_pd(spring, force, slid), slid};
}

#endif
