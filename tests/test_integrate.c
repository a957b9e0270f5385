/* Tests of solver/integrate: velocity Verlet against closed forms (free fall, terminal
 * velocity, energy of an undamped spring pair), NaN detection, escaping elements, and
 * bit-identical results for 1 and 2 OpenMP threads. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "force_pairs.h" /* the vector kernels, called one by one (upper_clean below) */
#include "integrate.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define KN  1.544871985e9
#define RHO 2500.0

static double rnd(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

static double disc_mass(double r) {
    return RHO * M_PI * r * r;
}

/* The default model constants (solver/base/model.c) with dt, damping, gravity chosen by the test.
 */
static cdem_model hand_model(double dt, double damping, double g) {
    cdem_model m;
    memset(&m, 0, sizeof m);
    const double r[4] = {50.0, 75.0, 100.0, 125.0};
    for (int k = 0; k < 4; k++) {
        m.radius[k] = r[k];
        m.mass[k] = disc_mass(r[k]);
    }
    m.min_mass = m.mass[0];
    m.max_radius = 125.0;
    m.average_radius = 87.5;
    m.kn = m.ks = KN;
    m.dt = dt;
    m.damping = damping;
    m.gravity = g;
    return m;
}

static cdem_params hand_params(cdem_material_model model) {
    cdem_params p;
    memset(&p, 0, sizeof p);
    p.material = model;
    p.first_slip = 1;
    p.density = RHO;
    p.element = (cdem_contact_material){.friction = 0.25, .cohesion = 5e9, .breaking_strain = 1.0};
    p.wall = p.element;
    p.fault = p.element;
    p.base = p.element;
    return p;
}

static void test_integrate_free_fall(void **st) {
    (void)st;
    const double dt = 0.028, g = 9.81;
    cdem_model m = hand_model(dt, 0.0, g);
    cdem_params p = hand_params(CDEM_MATERIAL_GRANULAR);
    cdem_integrator it;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, 100.0, 5000.0, 50.0, disc_mass(50.0), 1, 0, 0, NULL, &err),
        CDEM_OK);
    s.vx[0] = 2.0;
    s.vy[0] = 3.0;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    const int N = 1000;
    for (int k = 0; k < N; k++)
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
    const double t = N * dt;
    /* Verlet is exact for a constant force: only rounding remains */
    assert_float_equal(s.y[0], 5000.0 + 3.0 * t - 0.5 * g * t * t, 1e-9 * 5000.0);
    assert_float_equal(s.x[0], 100.0 + 2.0 * t, 1e-9 * 100.0);
    assert_float_equal(s.vy[0], 3.0 - g * t, 1e-9 * g * t);
    assert_float_equal(s.fy[0], -disc_mass(50.0) * g, 1e-9 * disc_mass(50.0) * g);
    cdem_integrator_free(&it);

    /* with damping: terminal velocity m g / c */
    const double c = dt * 3.0e9;
    m = hand_model(dt, c, g);
    s.vx[0] = s.vy[0] = 0.0;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    for (int k = 0; k < 2000; k++)
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
    const double vterm = -disc_mass(50.0) * g / c;
    assert_float_equal(s.vy[0], vterm, 1e-9 * fabs(vterm));
    assert_float_equal(s.fy[0], 0.0, 1e-6 * disc_mass(50.0) * g); /* force balance */
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

static double pair_energy(const cdem_state *s) {
    double e = 0.0;
    for (size_t i = 0; i < 2; i++)
        e += 0.5 * s->mass[i] * (s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i]);
    const double dx = s->x[1] - s->x[0], dy = s->y[1] - s->y[0];
    const double d = sqrt(dx * dx + dy * dy) - (s->radius[0] + s->radius[1]);
    return e + 0.5 * KN * d * d;
}

/* Two elements joined by an intact bond, no damping, no gravity: velocity Verlet keeps the
 * energy within 1e-3 (relative) over 1e4 steps of ~3 % of the period each. */
static void test_integrate_energy_conservation(void **st) {
    (void)st;
    const double dt = 0.005;
    cdem_model m = hand_model(dt, 0.0, 0.0);
    cdem_params p = hand_params(CDEM_MATERIAL_BONDED);
    cdem_integrator it;
    cdem_state s;
    cdem_error err;
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    assert_int_equal(
        cdem_state_append(&s, -1, 0.0, 0.0, 100.0, disc_mass(100.0), 1, 0, 0, NULL, &err), CDEM_OK);
    /* 2 m overlap along a diagonal, plus a transverse velocity (the pair also rotates) */
    assert_int_equal(cdem_state_append(&s, -1, 198.0 * 0.8, 198.0 * 0.6, 100.0, disc_mass(100.0), 1,
                                       0, 0, NULL, &err),
                     CDEM_OK);
    s.vx[1] = -0.3;
    s.vy[1] = 0.4;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_prime(&it, &s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_make_cohesive(&it, &s), 1);
    const double e0 = pair_energy(&s);
    double worst = 0.0, rmin = INFINITY, rmax = 0.0;
    for (int k = 0; k < 10000; k++) {
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        worst = fmax(worst, fabs(pair_energy(&s) - e0) / e0);
        const double r = hypot(s.x[1] - s.x[0], s.y[1] - s.y[0]);
        rmin = fmin(rmin, r);
        rmax = fmax(rmax, r);
    }
    assert_true(worst < 1e-3);
    assert_true(rmin < 199.0 && rmax > 201.0); /* it really oscillated through tension */
    long contacts, bonds;
    cdem_integrator_count(&it, &contacts, &bonds);
    assert_int_equal(bonds, 1);
    /* momentum: equal masses, zero net force: the centre of mass moves uniformly */
    const double t = 10000 * dt;
    assert_float_equal(0.5 * (s.x[0] + s.x[1]), 0.5 * (198.0 * 0.8 - 0.3 * t), 1e-6);
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}

/* A box of wall elements (base + two lateral walls) holding a hexagonal packing of free
 * elements (radii 95-100 m, spacing 199 m: touching or nearly so) with random velocities. */
static void make_box(cdem_state *s, int nx, int ny, uint64_t seed) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, (size_t)(nx * ny + 400), 0, &err), CDEM_OK);
    const double sp = 199.0, rw = 50.0;
    const double width = nx * sp + 2.0 * sp;
    for (double x = 0.0; x <= width + 1e-9; x += rw)
        assert_int_equal(
            cdem_state_append(s, -1, x, 0.0, rw, disc_mass(rw), 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
    for (double y = rw; y <= (ny + 2) * sp; y += rw) {
        assert_int_equal(
            cdem_state_append(s, -1, 0.0, y, rw, disc_mass(rw), 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
        assert_int_equal(
            cdem_state_append(s, -1, width, y, rw, disc_mass(rw), 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
    }
    uint64_t g = seed;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            double rad = 100.0 - 5.0 * rnd(&g);
            size_t k;
            double x = sp + i * sp + (j % 2) * 0.5 * sp;
            double y = rw + 100.0 + j * sp * 0.8660254037844386;
            assert_int_equal(cdem_state_append(s, -1, x, y, rad, disc_mass(rad), 1, 0, 0, &k, &err),
                             CDEM_OK);
            s->vx[k] = (rnd(&g) - 0.5) * 2.0;
            s->vy[k] = (rnd(&g) - 0.5) * 2.0;
        }
}

/* A material of the path tests: a granular law (any registered one, cdem_granular_law) under
 * one of the cohesion rules, or the bonded model. */
typedef struct {
    int bonded;                  /* 1: the bonded model (the law is not used) */
    cdem_granular_law law;       /* granular: the contact law */
    cdem_cohesive_contacts rule; /* granular: which contacts carry C0 */
    int first_slip;              /* granular: cohesion lost at the first slip */
} box_material;

/* The rules the vector path implements with masks, each with every law: cohesion of the
 * contacts of the end of equilibration lost at the first slip; forming contacts cohesive and
 * cohesion lost at separation; the initial contacts cohesive. */
static const struct {
    cdem_cohesive_contacts rule;
    int first_slip;
} box_rules[3] = {
    {CDEM_COHESIVE_EQUILIBRATED, 1}, {CDEM_COHESIVE_FORMED, 0}, {CDEM_COHESIVE_INITIAL, 1}};

static box_material granular_box(cdem_granular_law law, int rule) {
    return (box_material){0, law, box_rules[rule].rule, box_rules[rule].first_slip};
}

static const box_material box_default = {0, CDEM_LAW_NORMAL_COHESION, CDEM_COHESIVE_EQUILIBRATED,
                                         1};
static const box_material box_bonded = {1, CDEM_LAW_NORMAL_COHESION, CDEM_COHESIVE_EQUILIBRATED, 1};

/* make_box(1234) stepped `nsteps` times on `threads` threads with every loop threaded, the
 * pair forces by `path` (one this CPU runs), the touching pairs made cohesive half way;
 * threads = 0: a count that changes at every step (1, 2, 3, 2, 1, ...; the run loop's thread
 * governor may change it at any step). */
static void run_box_with(int threads, int nsteps, cdem_state *out, box_material mat,
                         cdem_force_path path) {
    static const int changing[4] = {1, 2, 3, 2};
    omp_set_num_threads(threads > 0 ? threads : 1);
    const double dt = 0.028;
    cdem_model m = hand_model(dt, dt * 3.0e9, 9.81);
    cdem_params p = hand_params(mat.bonded ? CDEM_MATERIAL_BONDED : CDEM_MATERIAL_GRANULAR);
    p.element.cohesion = 1e7;
    if (mat.bonded)
        p.element.breaking_strain = 0.002;
    p.granular_law = mat.law;
    p.cohesive_contacts = mat.rule;
    p.first_slip = mat.first_slip;
    cdem_integrator it;
    cdem_error err;
    make_box(out, 50, 40, 1234);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    cdem_integrator_enable_escape(&it);
    it.par_min = 0; /* thread every loop, whatever its size */
    if (path != CDEM_FORCE_PATH_AUTO) {
        assert_true(cdem_force_path_usable(path));
        it.force.path = path;
        /* the list build's distance test follows the path (scalar, or vector where usable) */
        it.nb.simd = path == CDEM_FORCE_PATH_SCALAR || !cdem_neighbour_avx2_usable() ? 1 : 2;
    }
    if (!mat.bonded && mat.rule == CDEM_COHESIVE_INITIAL)
        cdem_integrator_mark_initial(&it, out);
    for (int k = 0; k < nsteps; k++) {
        if (threads == 0)
            omp_set_num_threads(changing[k % 4]);
        assert_int_equal(cdem_integrator_step(&it, out, NULL, 0, 0.0, &err), CDEM_OK);
        if (k == nsteps / 2) {
            const long made = cdem_integrator_make_cohesive(&it, out);
            if (!mat.bonded && mat.rule == CDEM_COHESIVE_EQUILIBRATED)
                assert_true(made > 0);
        }
    }
    assert_true(it.nb.np > 2048);
    assert_true(it.nb.n_builds > 1);
    if (path != CDEM_FORCE_PATH_AUTO) {
        assert_int_equal(it.force.path, path);
    } else { /* chosen (and measured where there was a choice) by now */
        assert_true(it.force.path != CDEM_FORCE_PATH_AUTO);
        assert_true(cdem_force_path_usable(it.force.path));
        assert_int_equal(it.force.measure_left, 0);
    }
    cdem_integrator_free(&it);
}

static void run_box(int threads, int nsteps, cdem_state *out) {
    run_box_with(threads, nsteps, out, box_default, CDEM_FORCE_PATH_SCALAR);
}

static void assert_same_state(const cdem_state *a, const cdem_state *b) {
    assert_int_equal(a->n, b->n);
    assert_memory_equal(a->id, b->id, a->n * sizeof *a->id);
    assert_memory_equal(a->x, b->x, a->n * sizeof *a->x);
    assert_memory_equal(a->y, b->y, a->n * sizeof *a->y);
    assert_memory_equal(a->vx, b->vx, a->n * sizeof *a->vx);
    assert_memory_equal(a->vy, b->vy, a->n * sizeof *a->vy);
    assert_memory_equal(a->fx, b->fx, a->n * sizeof *a->fx);
    assert_memory_equal(a->fy, b->fy, a->n * sizeof *a->fy);
}

/* The vector paths this CPU runs (force.h, "Paths") into paths; returns how many. */
static int vector_paths(cdem_force_path paths[3]) {
    int n = 0;
    static const cdem_force_path all[2] = {CDEM_FORCE_PATH_AVX2, CDEM_FORCE_PATH_AVX512};
    for (int k = 0; k < 2; k++) {
        if (cdem_force_path_usable(all[k]))
            paths[n++] = all[k];
        else
            fprintf(stderr, "test_integrate: no %s path on this CPU: not compared\n",
                    cdem_force_path_name(all[k]));
    }
    return n;
}

/* Every force path of material `mat` gives the same bits, on 1, 2 and 3 threads (the scalar
 * path on 1 thread is the reference). */
static void assert_paths_agree(box_material mat) {
    cdem_state a, b;
    cdem_force_path paths[3];
    const int npaths = vector_paths(paths);
    run_box_with(1, 120, &a, mat, CDEM_FORCE_PATH_SCALAR);
    for (int threads = 1; threads <= 3; threads++) {
        for (int k = 0; k < npaths; k++) {
            run_box_with(threads, 120, &b, mat, paths[k]);
            assert_same_state(&a, &b);
            cdem_state_free(&b);
        }
        if (threads > 1) {
            run_box_with(threads, 120, &b, mat, CDEM_FORCE_PATH_SCALAR);
            assert_same_state(&a, &b);
            cdem_state_free(&b);
        }
    }
    cdem_state_free(&a);
}

/* The scalar and the vector force paths (force.h) give the same bits, on 1, 2 and 3 threads, for
 * every registered granular law (common/laws/laws.def, the tests' fixtures included: a law without
 * an AVX2 kernel takes its scalar kernel on the vector paths) under every cohesion rule, and for
 * the bonded model. A vector kernel that misses a case of its scalar kernel fails here, naming the
 * law. */
static void test_integrate_simd_paths(void **st) {
    (void)st;
    assert_int_equal(cdem_force_path_choose("scalar"), CDEM_FORCE_PATH_SCALAR);
    for (int law = 0; law < CDEM_LAW_COUNT; law++)
        for (int rule = 0; rule < 3; rule++) {
            print_message("law %s, rule %d\n", cdem_law_name((cdem_granular_law)law), rule);
            assert_paths_agree(granular_box((cdem_granular_law)law, rule));
        }
    assert_paths_agree(box_bonded);
}

/* The thread count changing from step to step (the run loop's governor, solver/run/governor.h)
 * gives the same bits as one thread throughout, on every force path and for the bonded
 * model. */
static void test_integrate_threads_change_mid_run(void **st) {
    (void)st;
    const box_material materials[2] = {box_default, box_bonded};
    cdem_force_path paths[3];
    const int npaths = vector_paths(paths);
    for (int k = 0; k < 2; k++) {
        cdem_state a, b;
        run_box_with(1, 120, &a, materials[k], CDEM_FORCE_PATH_SCALAR);
        for (int q = 0; q < npaths; q++) {
            run_box_with(0, 120, &b, materials[k], paths[q]);
            assert_same_state(&a, &b);
            cdem_state_free(&b);
        }
        run_box_with(0, 120, &b, materials[k], CDEM_FORCE_PATH_SCALAR);
        assert_same_state(&a, &b);
        cdem_state_free(&a);
        cdem_state_free(&b);
    }
    omp_set_num_threads(1);
}

/* A path left to the pass (AUTO): the environment's CDEM_SIMD, or, without one on a CPU with
 * AVX2 and AVX-512, the first passes alternating between the two and timing themselves
 * (force.h). Whatever it chose and while it measured, the bits are the scalar path's, on 1 and
 * 2 threads. */
static void test_integrate_measured_path(void **st) {
    (void)st;
    cdem_state a, b;
    run_box_with(1, 120, &a, box_default, CDEM_FORCE_PATH_SCALAR);
    for (int threads = 1; threads <= 2; threads++) {
        run_box_with(threads, 120, &b, box_default, CDEM_FORCE_PATH_AUTO);
        assert_same_state(&a, &b);
        cdem_state_free(&b);
    }
    cdem_state_free(&a);
    omp_set_num_threads(1);
}

#if defined(__x86_64__) && defined(__GNUC__)
#include <cpuid.h>

/* The processor's XINUSE bits (XGETBV with ECX = 1): bit 2 the upper halves of YMM0-15, bit
 * 6 the upper halves of ZMM0-15 in use. 0 when the processor cannot say. */
static int xinuse(uint64_t *bits) {
    unsigned a, b, c, d;
    if (!__get_cpuid(1, &a, &b, &c, &d) || !(c & (1u << 27))) /* OSXSAVE */
        return 0;
    if (!__get_cpuid_count(0xD, 1, &a, &b, &c, &d) || !(a & (1u << 2))) /* XGETBV ECX = 1 */
        return 0;
    uint32_t lo, hi;
    __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(1));
    *bits = ((uint64_t)hi << 32) | lo;
    return 1;
}

/* Every kernel of the vector paths (force_pairs.h) returns with the upper halves of the
 * vector registers zero (vzeroupper): else every SSE instruction of the baseline code after
 * it (the rest of the step, the list builds, the output) pays a penalty, up to 4 times its
 * time on the AMD EPYC measured (docs/performance.md, "Speed on every CPU"). Each kernel is
 * called on a stepped box and the processor asked right after (XINUSE); skipped where it
 * cannot say, or where it reports the registers in use even after a vzeroupper. */
static void test_integrate_vector_paths_leave_upper_clean(void **st) {
    (void)st;
    uint64_t bits;
    const uint64_t upper = (1u << 2) | (1u << 6);
    if (!cdem_force_path_usable(CDEM_FORCE_PATH_AVX2) || !xinuse(&bits)) {
        fprintf(stderr, "test_integrate: no AVX2 or no XINUSE here: not checked\n");
        return;
    }
    __asm__ volatile("vzeroupper");
    if (!xinuse(&bits) || (bits & upper)) {
        fprintf(stderr, "test_integrate: XINUSE reports the upper halves in use: not checked\n");
        return;
    }
    /* a box stepped on the AVX2 path: its list, state and packed elements */
    const double dt = 0.028;
    cdem_model m = hand_model(dt, dt * 3.0e9, 9.81);
    cdem_params p = hand_params(CDEM_MATERIAL_GRANULAR);
    cdem_integrator it;
    cdem_state s;
    cdem_error err;
    make_box(&s, 20, 20, 7);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    it.force.path = CDEM_FORCE_PATH_AVX2;
    for (int k = 0; k < 20; k++)
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
    const long n = (long)s.n, np = (long)it.nb.np;
    const cdem_force_pairs a = {.law = &it.law,
                                .dt = dt,
                                .x = s.x,
                                .y = s.y,
                                .vx = s.vx,
                                .vy = s.vy,
                                .pi = it.nb.pi,
                                .pj = it.nb.pj,
                                .R = it.nb.R,
                                .cls = it.nb.cls,
                                .hist = it.nb.hist,
                                .xs = it.nb.xs,
                                .pfx = it.nb.pfx,
                                .pfy = it.nb.pfy,
                                .pos4 = it.force.pos4};
    const cdem_force_elements e = {.kick = 1,
                                   .hdt = 0.5 * dt,
                                   .mass = s.mass,
                                   .x = s.x,
                                   .flags = s.flags,
                                   .radius = s.radius,
                                   .dt2 = dt * dt};
    const cdem_force_drift_args d = {.x = s.x,
                                     .y = s.y,
                                     .vx = s.vx,
                                     .vy = s.vy,
                                     .fx = s.fx,
                                     .fy = s.fy,
                                     .mass = s.mass,
                                     .flags = s.flags,
                                     .dt = dt,
                                     .pos4 = it.force.pos4};
    const cdem_force_kernels *ks[2] = {cdem_force_kernels_avx2(), cdem_force_kernels_avx512()};
    for (int k = 0; k < 2; k++) {
        if (!ks[k])
            continue;
        ks[k]->pack(s.x, s.y, s.vx, s.vy, 0, n, it.force.pos4);
        assert_true(xinuse(&bits) && !(bits & upper));
        ks[k]->pairs(&a, 0, np, (int32_t)n);
        assert_true(xinuse(&bits) && !(bits & upper));
        ks[k]->scatter(&a, 0, np, it.force.acc);
        assert_true(xinuse(&bits) && !(bits & upper));
        ks[k]->finish(&e, it.force.acc, s.vx, s.vy, s.fx, s.fy, 0, n);
        assert_true(xinuse(&bits) && !(bits & upper));
        ks[k]->drift(&d, 0, n);
        assert_true(xinuse(&bits) && !(bits & upper));
    }
    cdem_integrator_free(&it);
    cdem_state_free(&s);
}
#else
static void test_integrate_vector_paths_leave_upper_clean(void **st) {
    (void)st;
}
#endif

/* A settled-looking box stepper for the threaded tests: make_box(seed), granular law, dt
 * 0.028 s, every loop threaded (par_min 0), `steps` steps taken. */
static void open_box(cdem_integrator *it, cdem_state *s, uint64_t seed, int steps) {
    const double dt = 0.028;
    cdem_model m = hand_model(dt, dt * 3.0e9, 9.81);
    cdem_params p = hand_params(CDEM_MATERIAL_GRANULAR);
    cdem_error err;
    make_box(s, 50, 40, seed);
    assert_int_equal(cdem_integrator_init(it, &p, &m, &err), CDEM_OK);
    assert_int_equal(it->unstable_index, -1);
    it->par_min = 0;
    for (int k = 0; k < steps; k++)
        assert_int_equal(cdem_integrator_step(it, s, NULL, 0, 0.0, &err), CDEM_OK);
}

/* The unstable-motion guard (unstable_index, read by the run loop): the lowest index whose
 * |v| dt exceeds its radius after the step, the same for 1 and 3 threads; -1 when no element
 * does or the guard is off. */
static void test_integrate_unstable_guard(void **st) {
    (void)st;
    for (int threads = 1; threads <= 3; threads += 2) {
        omp_set_num_threads(threads);
        const double dt = 0.028;
        cdem_integrator it;
        cdem_error err;
        cdem_state s;
        open_box(&it, &s, 99, 0);
        it.unstable_guard = 1;
        for (int k = 0; k < 5; k++)
            assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        assert_int_equal(it.unstable_index, -1); /* a quiet box */
        /* two free elements far apart thrown at 3 radii per step */
        size_t hit[2] = {s.n / 3, (2 * s.n) / 3};
        for (int h = 0; h < 2; h++) {
            while (s.flags[hit[h]] & CDEM_FLAGS_BOUNDARY)
                hit[h]++;
            s.vx[hit[h]] = 3.0 * s.radius[hit[h]] / dt;
        }
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        long want = -1;
        for (size_t i = 0; i < s.n && want < 0; i++)
            if ((s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i]) * dt * dt > s.radius[i] * s.radius[i])
                want = (long)i;
        assert_true(want >= 0);
        assert_int_equal(it.unstable_index, want);
        it.unstable_guard = 0;
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        assert_int_equal(it.unstable_index, -1);
        cdem_integrator_free(&it);
        cdem_state_free(&s);
    }
}

/* The rebuild test made inside the force pass: a boundary element moved between steps (as
 * a boundary mode moves it, after the drift) or a free element drifting more than half the
 * skin triggers a list build in that very step, on 1 and on 2 threads (chunked test); a
 * smaller move does not. */
static void test_integrate_rebuild_test_in_force_pass(void **st) {
    (void)st;
    for (int threads = 1; threads <= 2; threads++) {
        omp_set_num_threads(threads);
        const double dt = 0.028;
        cdem_integrator it;
        cdem_error err;
        cdem_state s;
        open_box(&it, &s, 7, 3);
        const double half_skin = 0.5 * it.nb.skin;
        /* a wall element (never drifted) moved by 0.9 and then by 1.2 half skins */
        size_t w = 0;
        while (!(s.flags[w] & CDEM_FLAG_WALL))
            w++;
        long builds = it.nb.n_builds;
        s.y[w] = it.nb.y0[w] + 0.9 * half_skin;
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        assert_int_equal(it.nb.n_builds, builds);
        s.y[w] = it.nb.y0[w] + 1.2 * half_skin;
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        assert_int_equal(it.nb.n_builds, builds + 1);
        assert_true(fabs(it.nb.y0[w] - s.y[w]) == 0.0); /* built at the moved position */
        /* a free element given a velocity that drifts it 1.5 half skins in one step */
        size_t f = s.n - 1;
        while (s.flags[f] & CDEM_FLAGS_BOUNDARY)
            f--;
        builds = it.nb.n_builds;
        s.vx[f] = 1.5 * half_skin / dt;
        s.fx[f] = 0.0;
        s.fy[f] = 0.0;
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        assert_int_equal(it.nb.n_builds, builds + 1);
        cdem_integrator_free(&it);
        cdem_state_free(&s);
    }
}

static void test_integrate_deterministic_threads(void **st) {
    (void)st;
    cdem_state a, b;
    run_box(1, 200, &a);
    /* 2 threads: two chunks; 3 and 5 threads: more chunks than cores here, with cross pairs
     * reaching over several chunks (the chunks are cut by work, whatever the thread count) */
    for (int threads = 2; threads <= 5; threads += threads == 2 ? 1 : 2) {
        run_box(threads, 200, &b);
        assert_int_equal(a.n, b.n);
        assert_memory_equal(a.id, b.id, a.n * sizeof *a.id);
        assert_memory_equal(a.x, b.x, a.n * sizeof *a.x);
        assert_memory_equal(a.y, b.y, a.n * sizeof *a.y);
        assert_memory_equal(a.vx, b.vx, a.n * sizeof *a.vx);
        assert_memory_equal(a.vy, b.vy, a.n * sizeof *a.vy);
        assert_memory_equal(a.fx, b.fx, a.n * sizeof *a.fx);
        assert_memory_equal(a.fy, b.fy, a.n * sizeof *a.fy);
        if (threads < 5)
            cdem_state_free(&b);
    }
    /* and the elements actually moved and settled under gravity: nothing fell through */
    double ymin = INFINITY;
    for (size_t i = 0; i < a.n; i++)
        if (!(a.flags[i] & CDEM_FLAG_WALL))
            ymin = fmin(ymin, a.y[i]);
    assert_true(ymin > 50.0);
    cdem_state_free(&a);
    cdem_state_free(&b);
}

static void test_integrate_nan_and_escape(void **st) {
    (void)st;
    const double dt = 0.028;
    cdem_model m = hand_model(dt, dt * 3.0e9, 9.81);
    cdem_params p = hand_params(CDEM_MATERIAL_GRANULAR);
    cdem_integrator it;
    cdem_state s;
    cdem_error err;
    make_box(&s, 5, 3, 99);
    /* one element outside the right wall, falling: it must be removed, not lost silently */
    size_t k;
    assert_int_equal(
        cdem_state_append(&s, 777, 5000.0, 500.0, 50.0, disc_mass(50.0), 1, 0, 0, &k, &err),
        CDEM_OK);
    const size_t n0 = s.n;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    cdem_integrator_enable_escape(&it);
    long removed_steps = 0;
    for (int step = 0; step < 50; step++) {
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
        if (it.removal.n_removed_last) {
            assert_int_equal(it.removal.removed_ids[0], 777);
            removed_steps++;
        }
    }
    assert_int_equal(it.removal.n_removed, 1);
    assert_int_equal(removed_steps, 1);
    assert_int_equal(s.n, n0 - 1);
    for (size_t i = 0; i < s.n; i++)
        assert_int_not_equal(s.id[i], 777);
    /* NaN velocity: the next step reports the element and the step */
    int32_t victim = -1;
    for (size_t i = 0; i < s.n && victim < 0; i++)
        if (!(s.flags[i] & CDEM_FLAG_WALL)) {
            victim = s.id[i];
            s.vx[i] = NAN;
        }
    char expect[64];
    snprintf(expect, sizeof expect, "element id %d ", (int)victim);
    cdem_status stt = CDEM_OK;
    for (int step = 0; step < 3 && stt == CDEM_OK; step++)
        stt = cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err);
    assert_int_equal(stt, CDEM_ERR_NUMERIC);
    assert_non_null(strstr(err.msg, expect));
    assert_non_null(strstr(err.msg, "step 51"));
    assert_non_null(strstr(err.msg, "time step"));
    cdem_integrator_free(&it);
    cdem_integrator_free(NULL);
    cdem_state_free(&s);
    /* bad model constants are rejected with the value */
    m.dt = -1.0;
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "dt = -1"));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_integrate_free_fall),
        cmocka_unit_test(test_integrate_energy_conservation),
        cmocka_unit_test(test_integrate_deterministic_threads),
        cmocka_unit_test(test_integrate_simd_paths),
        cmocka_unit_test(test_integrate_measured_path),
        cmocka_unit_test(test_integrate_vector_paths_leave_upper_clean),
        cmocka_unit_test(test_integrate_threads_change_mid_run),
        cmocka_unit_test(test_integrate_unstable_guard),
        cmocka_unit_test(test_integrate_rebuild_test_in_force_pass),
        cmocka_unit_test(test_integrate_nan_and_escape),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
