/* test_bc_listric: listric and irregular faults with constant heave (bc_listric.c): fault
 * elements on the curve, footwall flagged and fixed, CH kinematics after k steps (fault
 * k du cos(db) horizontally away from the hanging wall, base and right wall k du sin(db)
 * vertically), reverse sense, inversion, errors, and an end-to-end cdem_run. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc_fixtures.h"
#include "contact.h"
#include "fault_file.h"
#include "scratch.h"

#include <unistd.h>

#define X0  1400.0 /* fault_location 0.35 x WIDTH */
#define DIP 45.0
#define K   40

static cdem_params listric_params(cdem_mode mode) {
    cdem_params p = fx_params(mode);
    p.fault_location = 0.35;
    p.fault_dip = DIP;
    p.fault_sense = CDEM_SENSE_NORMAL;
    p.kinematics = CDEM_KIN_CH;
    if (mode == CDEM_MODE_IRREGULAR_FAULT) {
        const char *d = getenv("CDEM_TEST_DATA");
        snprintf(p.fault_file, sizeof p.fault_file, "%s/fault_irregular.txt",
                 d && *d ? d : "tests/data");
    }
    return p;
}

/* Top of the free elements of the fixture (H of the listric law). */
static double fixture_top(void) {
    cdem_state s;
    fx_assembly(&s);
    double top = -INFINITY;
    for (size_t i = 0; i < s.n; i++)
        if (!(s.flags[i] & CDEM_FLAGS_BOUNDARY))
            top = fmax(top, s.y[i] + s.radius[i]);
    cdem_state_free(&s);
    return top;
}

/* Checks the geometry after init against the curve pl (basal dip db_deg): fault elements on
 * the ramp / curve / vertical top; no free or footwall element overlaps a fault element (the
 * ones cut by the fault were removed: n_before - n_cut_expected elements remain besides the
 * fault); footwall = exactly the elements left of the curve; left wall display-only. */
static void check_geometry(const cdem_state *s, const cdem_fault_polyline *pl, double db_deg,
                           const cdem_state *before) {
    const double db = db_deg * M_PI / 180.0;
    long nf = 0, nfw = 0, nfree = 0;
    double ylo = INFINITY, yhi = -INFINITY;
    for (size_t i = 0; i < s->n; i++) {
        const uint32_t f = s->flags[i];
        if (f & CDEM_FLAG_FAULT) {
            nf++;
            assert_true(f & CDEM_FLAG_MOVING);
            assert_float_equal(s->radius[i], RW, 0.0);
            ylo = fmin(ylo, s->y[i]);
            yhi = fmax(yhi, s->y[i]);
            double d;
            if (s->y[i] < 0.0) /* ramp along the basal segment */
                d = fabs((s->x[i] - X0) * sin(db) + s->y[i] * cos(db));
            else
                d = cdem_fault_file_distance(pl, s->x[i], s->y[i]);
            if (s->y[i] > pl->y[pl->n - 1])
                d = fabs(s->x[i] - pl->x[pl->n - 1]);
            if (d > 1e-6)
                fail_msg("fault element at (%g, %g) is %g m off the curve", s->x[i], s->y[i], d);
        } else if (f & CDEM_FLAG_WALL) {
            assert_false(f & CDEM_FLAG_FOOTWALL);
            assert_true(s->x[i] > 1.0 || s->y[i] < 1.0); /* the left wall is no longer a wall */
        } else if (s->layer[i] == 0) {
            assert_true(f & CDEM_FLAG_FOOTWALL); /* former left wall */
            assert_float_equal(s->x[i], 0.0, 0.0);
        } else {
            nfree++;
            const double xc = cdem_fault_file_x_at(pl, s->y[i]);
            const double dist = cdem_fault_file_distance(pl, s->x[i], s->y[i]);
            if (dist < s->radius[i] + RW)
                fail_msg("element %d at (%g, %g) overlaps the fault (%g m from the curve)",
                         (int)s->id[i], s->x[i], s->y[i], dist);
            const int expect = s->x[i] < xc;
            assert_int_equal((f & CDEM_FLAG_FOOTWALL) != 0, expect);
            nfw += expect;
            assert_int_equal(cdem_contact_class(f, 0), expect ? -1 : CDEM_CLASS_ELEMENT);
        }
    }
    assert_true(nf > 20);
    assert_true(nfw > 10 && nfw < nfree - 10);
    /* the removed elements are exactly the free ones cut by the fault */
    long cut = 0, kept_free = 0;
    for (size_t i = 0; i < before->n; i++) {
        if (before->flags[i] & CDEM_FLAGS_BOUNDARY)
            continue;
        const int is_cut =
            cdem_fault_file_distance(pl, before->x[i], before->y[i]) < before->radius[i] + RW;
        cut += is_cut;
        kept_free += !is_cut;
        assert_int_equal(fx_find(s, before->id[i]) == SIZE_MAX, is_cut);
    }
    assert_true(cut > 3);
    assert_int_equal(nfree, kept_free);
    assert_true(ylo < -((double)K * DPS + 3.0 * RW) * sin(db)); /* ramp below the base */
    assert_true(yhi > 1500.0 - RW);                             /* up to the top of the walls */
}

static void test_bc_listric_geometry(void **st) {
    (void)st;
    cdem_model m = fx_model(K);
    cdem_params p = listric_params(CDEM_MODE_LISTRIC_FAULT);
    cdem_state s, before;
    fx_assembly(&s);
    fx_assembly(&before);
    cdem_error err;
    cdem_bc bc;
    if (cdem_bc_init(&bc, &p, &m, &s, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    cdem_fault_polyline pl;
    assert_int_equal(
        cdem_fault_file_listric(X0, fixture_top(), DIP, CDEM_LISTRIC_SEGMENTS, &pl, &err), CDEM_OK);
    check_geometry(&s, &pl, DIP, &before);
    cdem_state_free(&before);
    char *v = fx_view(&bc);
    assert_non_null(strstr(v, "listric normal fault, constant heave (CH)"));
    assert_non_null(strstr(v, "basal dip 45.0 deg"));
    free(v);
    cdem_fault_file_free(&pl);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
}

static void test_bc_listric_irregular_geometry(void **st) {
    (void)st;
    cdem_model m = fx_model(K);
    cdem_params p = listric_params(CDEM_MODE_IRREGULAR_FAULT);
    cdem_state s, before;
    fx_assembly(&s);
    fx_assembly(&before);
    cdem_error err;
    cdem_bc bc;
    if (cdem_bc_init(&bc, &p, &m, &s, &err) != CDEM_OK)
        fail_msg("%s", err.msg);
    cdem_fault_polyline pl;
    assert_int_equal(cdem_fault_file_read(p.fault_file, X0, 25.0, &pl, &err), CDEM_OK);
    assert_int_equal(pl.n, 4);
    check_geometry(&s, &pl, atan2(400.0, 231.0) * 180.0 / M_PI, &before);
    cdem_state_free(&before);
    char *v = fx_view(&bc);
    assert_non_null(strstr(v, "irregular normal fault"));
    assert_non_null(strstr(v, "from the fault file"));
    free(v);
    cdem_fault_file_free(&pl);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
}

/* Runs K steps and checks every boundary element's displacement: fault elements `hx` in x,
 * the hanging-wall base (right of x0) and the right wall `vy` in y, the footwall display
 * elements and the footwall base (left of x0) `hx` in x with the fault (CH: the footwall is
 * rigid, so the fault is never drawn over it). */
static void check_kinematics(cdem_params p, double hx, double vy, double net_end) {
    fx_result r;
    fx_run(p, K, &r);
    long nf = 0, nb = 0, nfw = 0, nfix = 0; /* nfix: base elements left of x0 */
    for (size_t i = 0; i < r.s0.n; i++) {
        const uint32_t f = r.s0.flags[i];
        if (!(f & CDEM_FLAGS_BOUNDARY))
            continue;
        double dx, dy;
        fx_displacement(&r.s0, &r.s, r.s0.id[i], &dx, &dy);
        double ex = 0.0, ey = 0.0;
        if (f & CDEM_FLAG_FAULT) {
            ex = hx;
            nf++;
        } else if (f & CDEM_FLAG_FOOTWALL) {
            ex = hx;
            nfw++;
        } else if (r.s0.x[i] < X0) { /* the footwall's base: with the footwall */
            assert_false(f & CDEM_FLAG_MOVING);
            ex = hx;
            nfix++;
        } else {
            ey = vy;
            nb++;
        }
        if (fabs(dx - ex) > 1e-9 || fabs(dy - ey) > 1e-9)
            fail_msg("element %d (flags %u) at (%g, %g) moved (%g, %g), expected (%g, %g)",
                     (int)r.s0.id[i], (unsigned)f, r.s0.x[i], r.s0.y[i], dx, dy, ex, ey);
    }
    assert_true(nf > 20 && nb > 30 && nfw > 10);
    assert_true(nfix > 5); /* the footwall base (left of x0) rides with the footwall */
    /* after the motion no footwall display element overlaps a fault element */
    for (size_t i = 0; i < r.s.n; i++) {
        if (!(r.s.flags[i] & CDEM_FLAG_FOOTWALL) || r.s.layer[i] == 0)
            continue;
        for (size_t j = 0; j < r.s.n; j++)
            if ((r.s.flags[j] & CDEM_FLAG_FAULT) &&
                hypot(r.s.x[i] - r.s.x[j], r.s.y[i] - r.s.y[j]) <
                    r.s.radius[i] + r.s.radius[j] - 1e-6)
                fail_msg("footwall element %d at (%g, %g) overlaps fault element %d at (%g, %g)",
                         (int)r.s.id[i], r.s.x[i], r.s.y[i], (int)r.s.id[j], r.s.x[j], r.s.y[j]);
    }
    assert_float_equal(r.net_end, net_end, 1e-9);
    fx_result_free(&r);
}

static void test_bc_listric_normal_kinematics(void **st) {
    (void)st;
    const double d = DIP * M_PI / 180.0, u = (double)K * DPS;
    /* normal: the fault moves toward -x (away from the hanging wall), the base down */
    check_kinematics(listric_params(CDEM_MODE_LISTRIC_FAULT), -u * cos(d), -u * sin(d), u);
    /* irregular: the basal segment of the file dips atan2(400, 231) */
    const double db = atan2(400.0, 231.0);
    check_kinematics(listric_params(CDEM_MODE_IRREGULAR_FAULT), -u * cos(db), -u * sin(db), u);
}

static void test_bc_listric_reverse_and_inversion(void **st) {
    (void)st;
    const double d = DIP * M_PI / 180.0, u = (double)K * DPS;
    cdem_params p = listric_params(CDEM_MODE_LISTRIC_FAULT);
    p.fault_sense = CDEM_SENSE_REVERSE;
    check_kinematics(p, u * cos(d), u * sin(d), u);
    /* normal then reverse after half the steps: back to the start, net 0 */
    p = listric_params(CDEM_MODE_LISTRIC_FAULT);
    p.inversion = 1;
    p.inversion_percent = 50.0;
    check_kinematics(p, 0.0, 0.0, 0.0);
}

/* CD (mylar sheet): after K steps the sheet elements slid s down-dip along the fixed path
 * (s < 0: up-dip), exactly s (cos d, -sin d) on the ramp, (0, -s) on the vertical top and on
 * the curve in between; the hanging-wall base (right of x0) and the right wall moved
 * s (cos d, -sin d); the footwall (display elements and the base left of x0) not at all; the net
 * displacement is `net` (along the initial sense). Reverse and inversion use the same single sheet:
 * it is kinematic, so it drags the hanging wall up-dip as well as down-dip (the original's second
 * sheet for reverse motion, manual v4.0, is not needed; see docs/solver.md). */
static void check_cd(int sense, int inversion, double pct, double s, double net) {
    const double d = DIP * M_PI / 180.0;
    cdem_params p = listric_params(CDEM_MODE_LISTRIC_FAULT);
    p.kinematics = CDEM_KIN_CD;
    p.fault_sense = sense;
    p.inversion = inversion;
    p.inversion_percent = pct;
    const double H = fixture_top();
    cdem_fault_polyline pl;
    cdem_error err;
    assert_int_equal(cdem_fault_file_listric(X0, H, DIP, CDEM_LISTRIC_SEGMENTS, &pl, &err),
                     CDEM_OK);
    fx_result r;
    fx_run(p, K, &r);
    const double us = fabs(s);
    long nramp = 0, ntop = 0, ncurve = 0, nbase = 0, nfw = 0;
    for (size_t i = 0; i < r.s0.n; i++) {
        const uint32_t f = r.s0.flags[i];
        if (!(f & CDEM_FLAGS_BOUNDARY))
            continue;
        double dx, dy, ex = 0.0, ey = 0.0;
        fx_displacement(&r.s0, &r.s, r.s0.id[i], &dx, &dy);
        const double y0 = r.s0.y[i], y1 = y0 + dy;
        if (f & CDEM_FLAG_MYLAR) {
            assert_true(f & CDEM_FLAG_FAULT);
            if (y0 < 0.0 && y1 < 0.0) {
                ex = s * cos(d);
                ey = -s * sin(d);
                nramp++;
            } else if (y0 > H + 1e-6 && y1 > H + 1e-6) {
                ey = -s;
                ntop++;
            } else {
                ncurve++;
                const size_t b = fx_find(&r.s, r.s0.id[i]);
                const double yn = r.s.y[b], xn = r.s.x[b];
                const double off = yn < 0.0 ? fabs((xn - X0) * sin(d) + yn * cos(d))
                                            : cdem_fault_file_distance(&pl, xn, yn);
                assert_true(off < 1e-6);
                assert_true(hypot(dx, dy) <= us + 1e-9 && hypot(dx, dy) >= 0.99 * us);
                /* down-dip = toward +x and -y on this fault; up-dip the opposite */
                if (us > 0.0)
                    assert_true(s > 0.0 ? (dy < 0.0 && dx >= -1e-9) : (dy > 0.0 && dx <= 1e-9));
                continue;
            }
        } else if ((f & CDEM_FLAG_WALL) && r.s0.x[i] >= X0) {
            ex = s * cos(d);
            ey = -s * sin(d);
            nbase++;
        } else {
            nfw++; /* footwall display and footwall base: fixed in CD */
        }
        if (fabs(dx - ex) > 1e-9 || fabs(dy - ey) > 1e-9)
            fail_msg("element %d (flags %u) at (%g, %g) moved (%g, %g), expected (%g, %g)",
                     (int)r.s0.id[i], (unsigned)f, r.s0.x[i], y0, dx, dy, ex, ey);
    }
    assert_true(nramp > 2 && ntop > 10 && ncurve > 5 && nbase == 42 && nfw > 10);
    assert_float_equal(r.net_end, net, 1e-9);
    fx_result_free(&r);
    cdem_fault_file_free(&pl);
}

static void test_bc_listric_cd_kinematics(void **st) {
    (void)st;
    const double u = (double)K * DPS;
    check_cd(CDEM_SENSE_NORMAL, 0, 0.0, u, u);      /* normal: down-dip by u */
    check_cd(CDEM_SENSE_NORMAL, 1, 50.0, 0.0, 0.0); /* inverted at 50 %: back */
}

/* CD reverse and inversion: the single kinematic sheet slides up-dip (reverse) by u, and
 * with inversion of a reverse fault at 25 % it ends 0.5 u down-dip (net -0.5 u along the
 * initial reverse sense); inversion of a normal fault at 75 % ends 0.5 u down-dip. */
static void test_bc_listric_cd_reverse_and_inversion(void **st) {
    (void)st;
    const double u = (double)K * DPS;
    check_cd(CDEM_SENSE_REVERSE, 0, 0.0, -u, u);
    check_cd(CDEM_SENSE_REVERSE, 1, 25.0, 0.5 * u, -0.5 * u);
    check_cd(CDEM_SENSE_NORMAL, 1, 75.0, 0.5 * u, 0.5 * u);
}

static void test_bc_listric_errors(void **st) {
    (void)st;
    cdem_model m = fx_model(K);
    cdem_error err;
    cdem_bc bc;
    cdem_state s;
    fx_assembly(&s);
    cdem_params p = listric_params(CDEM_MODE_LISTRIC_FAULT);
    p.fault_location = 0.05;
    p.fault_dip = 20.0; /* the curve runs through the left wall */
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "would reach or pass it"));
    p = listric_params(CDEM_MODE_LISTRIC_FAULT);
    p.fault_dip = 0.0;
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "fault_dip = 0 degrees"));
    p = listric_params(CDEM_MODE_IRREGULAR_FAULT);
    const char *d = getenv("CDEM_TEST_DATA");
    snprintf(p.fault_file, sizeof p.fault_file, "%s/fault_bad_first.txt",
             d && *d ? d : "tests/data");
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "fault_bad_first.txt, line 1: first point"));
    /* issue 19, item 8: a vertex far above the model (it once laid fault elements up to
     * y = 1e9 m: 5 GB), a 1e-7 m segment, a folder as the vertex file */
    static const struct {
        const char *text; /* vertex file */
        const char *want; /* in the message */
    } bad[] = {
        {"1400 0\n1169 400\n1098 1e9\n", "line 3: point (1098, 1e+09) m lies far above the model"},
        {"1400 0\n1399.9999999 0.0000001\n1169 400\n", "line 2: the segment from (1400, 0) m"},
        {"1400 0\n1169 400\n-5 800\n", "line 3: point (-5, 800) m lies left of the model"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        p = listric_params(CDEM_MODE_IRREGULAR_FAULT);
        char name[64];
        snprintf(name, sizeof name, "bad_fault_%zu.txt", k);
        scratch_path(p.fault_file, sizeof p.fault_file, name);
        FILE *f = fopen(p.fault_file, "w");
        assert_non_null(f);
        fputs(bad[k].text, f);
        fclose(f);
        assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
        if (!strstr(err.msg, bad[k].want) || !strstr(err.msg, p.fault_file))
            fail_msg("fault file %zu: %s", k, err.msg);
        remove(p.fault_file);
    }
    p = listric_params(CDEM_MODE_IRREGULAR_FAULT);
    snprintf(p.fault_file, sizeof p.fault_file, "%s", scratch_root());
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_IO);
    assert_non_null(strstr(err.msg, "is a folder"));
    /* none of the refusals touched the state */
    for (size_t i = 0; i < s.n; i++)
        assert_false(s.flags[i] & (CDEM_FLAG_FOOTWALL | CDEM_FLAG_FAULT));
    cdem_state_free(&s);
}

/* listric-fault CH (normal), irregular-fault CH (reverse, tests/data/
 * fault_demo_irregular.txt) and listric-fault CD through cdem_run on a small default model. */
static void test_bc_listric_cdem_run(void **st) {
    (void)st;
    for (int k = 0; k < 3; k++) {
        cdem_params p;
        cdem_params_defaults(&p);
        p.fault.friction = 0.0;
        p.fault.cohesion = 0.0;
        if (k == 0) {
            p.mode = CDEM_MODE_LISTRIC_FAULT;
        } else if (k == 2) {
            cdem_params_defaults(&p); /* CD: the default frictional-cohesive fault */
            p.mode = CDEM_MODE_LISTRIC_FAULT;
            p.kinematics = CDEM_KIN_CD;
        } else {
            p.mode = CDEM_MODE_IRREGULAR_FAULT;
            p.fault_sense = CDEM_SENSE_REVERSE;
            const char *d = getenv("CDEM_TEST_DATA");
            snprintf(p.fault_file, sizeof p.fault_file, "%s/fault_demo_irregular.txt",
                     d && *d ? d : "tests/data");
        }
        cdem_increment_info last;
        cdem_model m;
        fx_cdem_run(p, k == 0 ? "test_bc_listric_run" : "test_bc_irregular_run", 300, &last, &m);
        assert_int_equal(last.step, m.equil_steps + 300);
        assert_int_equal(last.phase, CDEM_PHASE_DEFORMATION);
        assert_float_equal(last.net_displacement, 300.0 * m.displacement_per_step, 1e-9);
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_listric_geometry),
        cmocka_unit_test(test_bc_listric_irregular_geometry),
        cmocka_unit_test(test_bc_listric_normal_kinematics),
        cmocka_unit_test(test_bc_listric_reverse_and_inversion),
        cmocka_unit_test(test_bc_listric_cd_kinematics),
        cmocka_unit_test(test_bc_listric_cd_reverse_and_inversion),
        cmocka_unit_test(test_bc_listric_errors),
        cmocka_unit_test(test_bc_listric_cdem_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
