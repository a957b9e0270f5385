/* Tests of the heterogeneity, overburden and erosion features (solver/contact, integrate):
 * per-pair material rules evaluated on two-element systems against the closed-form Coulomb
 * limit mu Fn + C0 and bond reach r0 R, the weak/light interval mass, the overburden force
 * on the surface elements, and erosion removing exactly the elements above the level. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "contact.h"
#include "h5format.h"
#include "integrate.h"
#include "run.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define KN  1.0e9
#define KS  5.0e8
#define RHO 2500.0

static cdem_params het_params(cdem_material_model model) {
    cdem_params p;
    memset(&p, 0, sizeof p);
    p.material = model;
    p.first_slip = 1;
    p.granular_law = CDEM_LAW_COULOMB; /* limits below: mu Fn + C0 of each class */
    p.settling_friction = 1.0;
    p.density = RHO;
    p.element =
        (cdem_contact_material){.friction = 0.25, .cohesion = 5.0e6, .breaking_strain = 0.02};
    p.wall = (cdem_contact_material){.friction = 0.5, .cohesion = 1.0e6, .breaking_strain = 0.05};
    p.fault = (cdem_contact_material){.friction = 0.0, .cohesion = 0.0, .breaking_strain = 0.01};
    p.base = (cdem_contact_material){.friction = NAN, .cohesion = NAN, .breaking_strain = NAN};
    p.weak_thickness_percent = 30.0;
    p.weak_strength_percent = 30.0;
    p.weak_density_percent = 80.0;
    p.layered_friction_value = 0.6;
    return p;
}

static cdem_contact_law law_of(const cdem_params *p) {
    cdem_contact_law law;
    cdem_error err;
    assert_int_equal(cdem_contact_law_init(&law, p, KN, KS, &err), CDEM_OK);
    return law;
}

/* Shear force of a cohesive pair overlapping by 1 m (Fn = KN) pushed far past its strength
 * in one evaluation: the Coulomb limit mu Fn + C0 of its class. */
static double shear_limit(const cdem_contact_law *law, int cls) {
    const double R = 200.0, delta = 1.0;
    double xs = 0.0, fx = 0.0, fy = 0.0;
    uint8_t h = CDEM_PAIR_TOUCH | CDEM_PAIR_COHESIVE;
    cdem_contact_eval(law, cls, R - delta, 0.0, R, 0.0, 100.0, 0.1, &xs, &h, NULL, &fx, &fy);
    assert_float_equal(fx, -KN * delta, 1e-6 * KN);
    return fabs(fy);
}

/* 1 when a bonded pair stretched by `gap` (r - R) keeps its bond. */
static int bond_holds(const cdem_contact_law *law, int cls, double gap) {
    const double R = 200.0;
    double xs = 0.0, fx = 0.0, fy = 0.0;
    uint8_t h = CDEM_PAIR_BONDED;
    cdem_contact_eval(law, cls, R + gap, 0.0, R, 0.0, 0.0, 0.1, &xs, &h, NULL, &fx, &fy);
    if (h & CDEM_PAIR_BONDED) /* intact: tension Kn gap pulls i towards j (+x) */
        assert_float_equal(fx, KN * gap, 1e-6 * KN * gap);
    return (h & CDEM_PAIR_BONDED) != 0;
}

static void test_heterogeneity_flexural_slip(void **st) {
    (void)st;
    cdem_params p = het_params(CDEM_MATERIAL_GRANULAR);
    p.flexural_slip = 1;
    cdem_contact_law law = law_of(&p);
    const double full = 0.25 * KN + 5.0e6;
    /* different pre-growth layers: no strength at all */
    const int slip = cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, 3, 0u, 4, 0u);
    assert_int_equal(slip, CDEM_CLASS_SLIP);
    assert_float_equal(shear_limit(&law, slip), 0.0, 1e-9);
    /* same layer: the material strength */
    const int same = cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, 4, 0u, 4, 0u);
    assert_int_equal(same, CDEM_CLASS_ELEMENT);
    assert_float_equal(shear_limit(&law, same), full, 1e-9 * full);
    /* growth layers and walls are not pre-growth layers; wall/fault classes are kept */
    assert_int_equal(cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, 24, 0u, 25, 0u),
                     CDEM_CLASS_ELEMENT);
    assert_int_equal(cdem_contact_refine(&law, CDEM_CLASS_WALL, 3, 0u, 4, 0u), CDEM_CLASS_WALL);
    /* off: no slip class */
    p.flexural_slip = 0;
    cdem_contact_law off = law_of(&p);
    assert_int_equal(cdem_contact_refine(&off, CDEM_CLASS_ELEMENT, 3, 0u, 4, 0u),
                     CDEM_CLASS_ELEMENT);
}

/* Style weak-layers (the original's versions 4.1-4.2): every contact of an element of layer
 * 4, 8, 12, 16 or 20 has no strength, whatever the other layer; other layer contacts keep
 * theirs. */
static void test_heterogeneity_flexural_slip_weak_layers(void **st) {
    (void)st;
    cdem_params p = het_params(CDEM_MATERIAL_GRANULAR);
    p.flexural_slip = 1;
    p.flexural_slip_style = CDEM_FLEX_WEAK_LAYERS;
    cdem_contact_law law = law_of(&p);
    for (int a = 1; a <= 24; a++)
        for (int b = 1; b <= 24; b++) {
            const int weak = (a % 4 == 0 && a <= 20) || (b % 4 == 0 && b <= 20);
            assert_int_equal(cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, a, 0u, b, 0u),
                             weak ? CDEM_CLASS_SLIP : CDEM_CLASS_ELEMENT);
        }
    assert_true(cdem_contact_weak_layer(20) && !cdem_contact_weak_layer(24) &&
                !cdem_contact_weak_layer(0) && !cdem_contact_weak_layer(28));
    /* growth layers and the wall/fault classes are never refined */
    assert_int_equal(cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, 4, 0u, 25, 0u),
                     CDEM_CLASS_ELEMENT);
    assert_int_equal(cdem_contact_refine(&law, CDEM_CLASS_WALL, 4, 0u, 4, 0u), CDEM_CLASS_WALL);
}

/* Two touching elements through the integrator: at the end of equilibration a bond is
 * created between same-layer elements only. */
static long bonds_made(int layer_a, int layer_b) {
    cdem_params p = het_params(CDEM_MATERIAL_BONDED);
    p.flexural_slip = 1;
    cdem_model m;
    memset(&m, 0, sizeof m);
    const double r[4] = {50.0, 75.0, 100.0, 125.0};
    for (int k = 0; k < 4; k++) {
        m.radius[k] = r[k];
        m.mass[k] = RHO * M_PI * r[k] * r[k];
    }
    m.min_mass = m.mass[0];
    m.max_radius = 125.0;
    m.kn = KN;
    m.ks = KS;
    m.dt = 0.01;
    cdem_error err;
    cdem_state s;
    cdem_integrator it;
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, 0.0, 0.0, 100.0, m.mass[2], layer_a, 0u, 0, NULL, &err), CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, 199.0, 0.0, 100.0, m.mass[2], layer_b, 0u, 0, NULL, &err),
        CDEM_OK);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    const long made = cdem_integrator_make_cohesive(&it, &s);
    long contacts = 0, bonds = 0;
    cdem_integrator_count(&it, &contacts, &bonds);
    assert_int_equal(contacts, 1);
    assert_int_equal(bonds, made);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
    return made;
}

static void test_heterogeneity_flexural_slip_no_bond(void **st) {
    (void)st;
    assert_int_equal(bonds_made(3, 4), 0);
    assert_int_equal(bonds_made(3, 3), 1);
    assert_int_equal(bonds_made(0, 0), 1); /* before layering: no flexural slip */
}

static void test_heterogeneity_weak_strength(void **st) {
    (void)st;
    cdem_params p = het_params(CDEM_MATERIAL_GRANULAR);
    p.weak_interval = CDEM_WEAK_LOWER;
    cdem_contact_law law = law_of(&p);
    const double full = 0.25 * KN + 5.0e6;
    /* a mixed pair (one weak element) uses the weak values */
    const int mixed = cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, 1, CDEM_FLAG_WEAK, 1, 0u);
    assert_int_equal(mixed, CDEM_CLASS_WEAK);
    assert_float_equal(shear_limit(&law, mixed), 0.30 * full, 1e-9 * full);
    assert_int_equal(
        cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, 1, CDEM_FLAG_WEAK, 1, CDEM_FLAG_WEAK),
        CDEM_CLASS_WEAK);
    assert_int_equal(cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, 1, 0u, 1, 0u),
                     CDEM_CLASS_ELEMENT);
    assert_float_equal(shear_limit(&law, CDEM_CLASS_ELEMENT), full, 1e-9 * full);

    /* bonded: the breaking strain is 30 % of 0.02, i.e. reach 0.006 x 200 = 1.2 m */
    cdem_params pb = het_params(CDEM_MATERIAL_BONDED);
    pb.weak_interval = CDEM_WEAK_UPPER;
    cdem_contact_law lb = law_of(&pb);
    assert_true(bond_holds(&lb, CDEM_CLASS_WEAK, 1.1));
    assert_false(bond_holds(&lb, CDEM_CLASS_WEAK, 1.3));
    assert_true(bond_holds(&lb, CDEM_CLASS_ELEMENT, 1.3)); /* material reach 4 m */
    assert_true(bond_holds(&lb, CDEM_CLASS_ELEMENT, 3.9));
    assert_false(bond_holds(&lb, CDEM_CLASS_ELEMENT, 4.1));

    /* a strength percentage outside 0..100 is refused by name */
    pb.weak_strength_percent = 150.0;
    cdem_contact_law bad;
    cdem_error err;
    assert_int_equal(cdem_contact_law_init(&bad, &pb, KN, KS, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "weak_strength_percent = 150"));
}

/* 10 free elements at y = 0, 100, ..., 900 (mass density pi r^2) and one wall element. */
static void column_state(cdem_state *s, double r) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, 16, 0, &err), CDEM_OK);
    for (int k = 0; k < 10; k++)
        assert_int_equal(cdem_state_append(s, -1, 300.0 * k, 100.0 * k, r, RHO * M_PI * r * r, 0,
                                           0u, 0, NULL, &err),
                         CDEM_OK);
    assert_int_equal(cdem_state_append(s, -1, 0.0, 2000.0, r, RHO * M_PI * r * r, 0, CDEM_FLAG_WALL,
                                       0, NULL, &err),
                     CDEM_OK);
}

static void test_heterogeneity_weak_mass(void **st) {
    (void)st;
    const double r = 75.0, m0 = RHO * M_PI * r * r;
    cdem_error err;
    for (int upper = 0; upper <= 1; upper++) {
        cdem_params p = het_params(CDEM_MATERIAL_GRANULAR);
        p.weak_interval = upper ? CDEM_WEAK_UPPER : CDEM_WEAK_LOWER;
        cdem_state s;
        column_state(&s, r);
        long marked = -1;
        assert_int_equal(cdem_contact_assign_weak(&p, &s, &marked, &err), CDEM_OK);
        /* 30 % of the 900 m span of centres: 270 m -> 3 elements at either end */
        assert_int_equal(marked, 3);
        for (size_t i = 0; i < s.n; i++) {
            const int wall = (s.flags[i] & CDEM_FLAG_WALL) != 0;
            const int in = !wall && (upper ? s.y[i] >= 630.0 : s.y[i] <= 270.0);
            assert_int_equal((s.flags[i] & CDEM_FLAG_WEAK) != 0, in);
            assert_float_equal(s.mass[i], (in ? 0.80 : 1.0) * m0, 1e-12 * m0);
        }
        cdem_state_free(&s);
    }
    /* off: nothing changes */
    cdem_params p = het_params(CDEM_MATERIAL_GRANULAR);
    cdem_state s;
    column_state(&s, r);
    long marked = -1;
    assert_int_equal(cdem_contact_assign_weak(&p, &s, &marked, &err), CDEM_OK);
    assert_int_equal(marked, 0);
    /* a density percentage of 0 is refused by name */
    p.weak_interval = CDEM_WEAK_LOWER;
    p.weak_density_percent = 0.0;
    assert_int_equal(cdem_contact_assign_weak(&p, &s, &marked, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "weak_density_percent = 0"));
    cdem_state_free(&s);
}

static void test_heterogeneity_layered_friction(void **st) {
    (void)st;
    cdem_params p = het_params(CDEM_MATERIAL_GRANULAR);
    p.layered_friction = 1;
    cdem_contact_law law = law_of(&p);
    const double full = 0.25 * KN + 5.0e6, layered = 0.6 * KN + 5.0e6;
    for (int L = 1; L <= 24; L++) {
        const int expect = (L >= 5 && L <= 8) || (L >= 13 && L <= 16) || (L >= 21 && L <= 24);
        assert_int_equal(cdem_contact_layered_layer(L), expect);
        const int cls = cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, L, 0u, L, 0u);
        assert_int_equal(cls, expect ? CDEM_CLASS_LAYERED : CDEM_CLASS_ELEMENT);
        const double lim = shear_limit(&law, cls);
        assert_float_equal(lim, expect ? layered : full, 1e-9 * full);
    }
    assert_int_equal(cdem_contact_layered_layer(0), 0);
    assert_int_equal(cdem_contact_layered_layer(25), 0);
    /* mixed pair (layer 4 with layer 5): either in a layered layer -> layered friction */
    assert_int_equal(cdem_contact_refine(&law, CDEM_CLASS_ELEMENT, 4, 0u, 5, 0u),
                     CDEM_CLASS_LAYERED);
    /* with a weak element: layered friction x the weak percentage */
    p.weak_interval = CDEM_WEAK_LOWER;
    cdem_contact_law lw = law_of(&p);
    const int both = cdem_contact_refine(&lw, CDEM_CLASS_ELEMENT, 6, CDEM_FLAG_WEAK, 6, 0u);
    assert_int_equal(both, CDEM_CLASS_LAYERED_WEAK);
    assert_float_equal(shear_limit(&lw, both), 0.30 * layered, 1e-9 * layered);
}

static cdem_model plain_model(void) {
    cdem_model m;
    memset(&m, 0, sizeof m);
    const double r[4] = {50.0, 75.0, 100.0, 125.0};
    for (int k = 0; k < 4; k++) {
        m.radius[k] = r[k];
        m.mass[k] = RHO * M_PI * r[k] * r[k];
    }
    m.min_mass = m.mass[0];
    m.max_radius = 125.0;
    m.kn = KN;
    m.ks = KS;
    m.dt = 0.01;
    return m;
}

static void test_heterogeneity_overburden_surface(void **st) {
    (void)st;
    const double pressure = 2.0e6, r = 50.0;
    cdem_params p = het_params(CDEM_MATERIAL_GRANULAR);
    cdem_model m = plain_model(); /* no gravity, no damping: fy is the overburden alone */
    cdem_error err;
    cdem_state s;
    assert_int_equal(cdem_state_init(&s, 128, 0, &err), CDEM_OK);
    /* 20 x 4 elements 150 m apart (not touching), and a wall element above them all */
    for (int row = 0; row < 4; row++)
        for (int col = 0; col < 20; col++)
            assert_int_equal(cdem_state_append(&s, -1, 150.0 * col, 150.0 * row, r,
                                               RHO * M_PI * r * r, 0, 0u, 0, NULL, &err),
                             CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 0.0, 5000.0, r, RHO * M_PI * r * r, 0,
                                       CDEM_FLAG_WALL, 0, NULL, &err),
                     CDEM_OK);
    cdem_integrator it;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_loads_set_overburden(&it.loads, pressure, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    const double w = 2.0 * 125.0, width = 150.0 * 19 + 2.0 * r;
    double total = 0.0;
    long surface = 0;
    for (size_t i = 0; i < s.n; i++) {
        const int top = (s.flags[i] & CDEM_FLAG_SURFACE) != 0;
        if (top) {
            assert_float_equal(s.y[i], 450.0, 1e-9); /* only the top row */
            assert_float_equal(s.fy[i], -pressure * w, 1e-9 * pressure * w);
            surface++;
        } else if (!(s.flags[i] & CDEM_FLAG_WALL)) {
            assert_float_equal(s.fy[i], 0.0, 1e-9);
        }
        assert_float_equal(s.fx[i], 0.0, 1e-9);
        total += s.fy[i] * !(s.flags[i] & CDEM_FLAG_WALL);
    }
    assert_int_equal(surface, it.loads.n_surface);
    assert_true(fabs(-total - pressure * width) <= pressure * w);
    /* the surface is found again: raise one element of row 1 above the top row */
    size_t lifted = SIZE_MAX;
    for (size_t i = 0; i < s.n && lifted == SIZE_MAX; i++)
        if (s.y[i] == 150.0 && s.x[i] == 1500.0)
            lifted = i;
    assert_true(lifted != SIZE_MAX);
    s.y[lifted] = 1000.0;
    assert_int_equal(cdem_loads_find_surface(&it.loads, &s, &err), CDEM_OK);
    assert_true(s.flags[lifted] & CDEM_FLAG_SURFACE);
    for (size_t i = 0; i < s.n; i++)
        if ((s.flags[i] & CDEM_FLAG_SURFACE) && i != lifted)
            assert_float_equal(s.y[i], 450.0, 1e-9);
    assert_int_equal(it.loads.n_surface, surface);
    /* a negative pressure is refused by name */
    assert_int_equal(cdem_loads_set_overburden(&it.loads, -1.0, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "overburden_pressure = -1"));
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

static void test_heterogeneity_erosion_removes_above(void **st) {
    (void)st;
    cdem_params p = het_params(CDEM_MATERIAL_GRANULAR);
    cdem_model m = plain_model();
    cdem_error err;
    cdem_state s;
    const double r = 75.0;
    column_state(&s, r); /* free elements at y = 0..900, a wall element at 2000 */
    /* a touching pair straddling the level: 440 (kept) and 440 + 149 = 589 (eroded) */
    assert_int_equal(
        cdem_state_append(&s, 500, 5000.0, 440.0, r, RHO * M_PI * r * r, 0, 0u, 0, NULL, &err),
        CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, 501, 5000.0, 589.0, r, RHO * M_PI * r * r, 0, 0u, 0, NULL, &err),
        CDEM_OK);
    cdem_integrator it;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    for (size_t i = 0; i < s.n; i++)
        if (s.id[i] == 500)
            assert_true(s.fy[i] < 0.0); /* pushed down by 501 */
    const size_t n0 = s.n;
    long count = -1;
    assert_int_equal(cdem_integrator_erode(&it, &s, 450.0, &count, &err), CDEM_OK);
    /* above 450: 500, 600, 700, 800, 900 and element 501 -> 6; the wall stays */
    assert_int_equal(count, 6);
    assert_int_equal((long)it.removal.n_removed_last, 6);
    assert_int_equal(s.n, n0 - 6);
    /* ids are assigned from 0 in append order: 5..9 are the elements at y = 500..900 */
    const int32_t expect_ids[6] = {5, 6, 7, 8, 9, 501};
    for (int e = 0; e < 6; e++) {
        int found = 0;
        for (size_t k = 0; k < it.removal.n_removed_last; k++)
            found += it.removal.removed_ids[k] == expect_ids[e];
        assert_int_equal(found, 1);
    }
    int wall_kept = 0;
    for (size_t i = 0; i < s.n; i++) {
        if (s.flags[i] & CDEM_FLAG_WALL) {
            wall_kept = 1;
            continue;
        }
        assert_true(s.y[i] <= 450.0);
        if (s.id[i] == 500)
            assert_float_equal(s.fy[i], 0.0, 1e-9); /* its neighbour is gone */
    }
    assert_true(wall_kept);
    /* nothing left above the level: a second pass removes nothing */
    assert_int_equal(cdem_integrator_erode(&it, &s, 450.0, &count, &err), CDEM_OK);
    assert_int_equal(count, 0);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

/* End to end: a small reverse-fault model with an upper light interval, flexural slip and
 * erosion at the initial top runs (no refusal); increment 0 flags exactly the upper interval,
 * every increment carries the flags, and no free element of a deformation increment is
 * above the level. (Masses are not in the file; test_heterogeneity_weak_mass covers them.) */
static void test_heterogeneity_run_end_to_end(void **st) {
    (void)st;
    char path[1024];
    scratch_path(path, sizeof path, "test_heterogeneity_run.h5");
    cdem_params p;
    cdem_params_defaults(&p);
    p.width = 10.0;
    p.height = 2.5;
    p.equilibration = 100.0;
    p.runtime = 250.0;
    p.fault_sense = CDEM_SENSE_REVERSE;
    p.fault_dip = 60.0;
    p.flexural_slip = 1;
    p.weak_interval = CDEM_WEAK_UPPER;
    p.weak_thickness_percent = 40.0;
    p.weak_strength_percent = 50.0;
    p.weak_density_percent = 80.0;
    p.erosion = 1;
    p.erosion_base_level = 1.0;
    cdem_error err;
    cdem_model m;
    assert_int_equal(cdem_params_validate(&p, NULL, &err), CDEM_OK);
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    if (cdem_run(&p, &o, &err) != CDEM_OK)
        fail_msg("cdem_run: %s", err.msg);
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "completed");
    const size_t ninc = cdem_h5_reader_increment_count(r);
    size_t ie = 0;
    assert_int_equal(cdem_h5_reader_find_increment(r, "equil", &ie, &err), CDEM_OK);
    cdem_state s;
    memset(&s, 0, sizeof s);
    cdem_increment_info info;
    double level = INFINITY;
    long weak0 = -1;
    size_t n_equil = 0, n_last = 0;
    for (size_t k = 0; k < ninc; k++) {
        assert_int_equal(cdem_h5_reader_load_increment(r, k, &s, &info, &err), CDEM_OK);
        long weak = 0;
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < s.n; i++) {
            if (s.flags[i] & CDEM_FLAGS_BOUNDARY)
                continue;
            lo = fmin(lo, s.y[i]);
            hi = fmax(hi, s.y[i]);
            weak += (s.flags[i] & CDEM_FLAG_WEAK) != 0;
            if (k > ie)
                assert_true(s.y[i] <= level);
        }
        if (k == 0) {
            /* membership from the initial heights: the upper 40 % of the centre span */
            for (size_t i = 0; i < s.n; i++) {
                const int in =
                    !(s.flags[i] & CDEM_FLAGS_BOUNDARY) && s.y[i] >= hi - 0.40 * (hi - lo);
                assert_int_equal((s.flags[i] & CDEM_FLAG_WEAK) != 0, in);
            }
            weak0 = weak;
        }
        /* the flag is kept for life; only erosion (of the top, weak here) lowers the count */
        assert_true(weak > 0 && weak <= weak0);
        if (k == ie) {
            level = lo + 1.0 * (hi - lo); /* docs/solver.md 7.4 */
            n_equil = s.n;
        }
        n_last = s.n;
        cdem_state_free(&s);
    }
    assert_true(isfinite(level));
    assert_true(n_last < n_equil); /* the uplifted hanging wall was eroded */
    cdem_h5_reader_close(r);
    remove(path);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_heterogeneity_flexural_slip),
        cmocka_unit_test(test_heterogeneity_flexural_slip_weak_layers),
        cmocka_unit_test(test_heterogeneity_flexural_slip_no_bond),
        cmocka_unit_test(test_heterogeneity_weak_strength),
        cmocka_unit_test(test_heterogeneity_weak_mass),
        cmocka_unit_test(test_heterogeneity_layered_friction),
        cmocka_unit_test(test_heterogeneity_overburden_surface),
        cmocka_unit_test(test_heterogeneity_erosion_removes_above),
        cmocka_unit_test(test_heterogeneity_run_end_to_end),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
