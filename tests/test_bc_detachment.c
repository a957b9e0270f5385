/* Tests of solver/bc_detachment: the right wall moves inward by exactly k x
 * displacement_per_step ("right"), or both lateral walls by that much each ("both"); the
 * base never moves; the net displacement is the total shortening (k or 2 k x
 * displacement_per_step); increments come every display interval of each wall's
 * displacement; base contacts are wall-class contacts; errors/view. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc_fixtures.h"
#include "contact.h"
#include "scratch.h"

#include <stdio.h>
#include <stdlib.h>

static void check_kinematics(cdem_walls_choice walls) {
    const long K = 600;
    cdem_params p = fx_params(CDEM_MODE_DETACHMENT);
    p.detachment_walls = walls;
    fx_result r;
    fx_run(p, K, &r);
    const double w = (double)K * DPS;                        /* each moving wall */
    const double u = walls == CDEM_WALLS_BOTH ? 2.0 * w : w; /* total shortening */
    long n_left = 0, n_right = 0, n_base = 0;
    for (size_t i = 0; i < r.s0.n; i++) {
        const uint32_t f = r.s0.flags[i];
        if (!(f & CDEM_FLAG_WALL))
            continue;
        assert_true(!(f & CDEM_FLAG_FAULT));
        double dx, dy;
        fx_displacement(&r.s0, &r.s, r.s0.id[i], &dx, &dy);
        assert_true(dy == 0.0);
        if (r.s0.y[i] == 0.0) { /* the base never moves */
            assert_true(dx == 0.0);
            assert_true(!(f & CDEM_FLAG_MOVING));
            n_base++;
        } else if (r.s0.x[i] == WIDTH) { /* right wall: left by w */
            assert_float_equal(dx, -w, 1e-9 * u);
            n_right++;
        } else { /* left wall: right by w with "both", else still */
            assert_float_equal(dx, walls == CDEM_WALLS_BOTH ? w : 0.0, 1e-9 * u);
            assert_int_equal((f & CDEM_FLAG_MOVING) != 0, walls == CDEM_WALLS_BOTH);
            n_left++;
        }
    }
    assert_int_equal(n_base, 41);
    assert_int_equal(n_right, 15);
    assert_int_equal(n_left, 15);
    /* net = total shortening = the sum of the walls' inward displacements */
    assert_float_equal(r.net_mid, 0.5 * u, 1e-9);
    assert_float_equal(r.net_end, u, 1e-9);
    assert_float_equal(r.net_end, (walls == CDEM_WALLS_BOTH ? 2.0 : 1.0) * w, 1e-9);
    assert_int_equal(r.removed, 0);
    assert_int_equal(r.s.n, r.s0.n);
    fx_result_free(&r);
}

static void test_bc_detachment_right_wall(void **st) {
    (void)st;
    check_kinematics(CDEM_WALLS_RIGHT);
}

static void test_bc_detachment_both_walls(void **st) {
    (void)st;
    check_kinematics(CDEM_WALLS_BOTH);
}

/* The base is a wall: its contacts with elements use the wall material. */
static void test_bc_detachment_base_contacts_are_wall_class(void **st) {
    (void)st;
    assert_int_equal(cdem_contact_class(CDEM_FLAG_WALL, 0), CDEM_CLASS_WALL);
    assert_int_equal(cdem_contact_class(CDEM_FLAG_WALL | CDEM_FLAG_MOVING, 0), CDEM_CLASS_WALL);
    assert_int_equal(cdem_contact_class(CDEM_FLAG_WALL, CDEM_FLAG_WALL | CDEM_FLAG_MOVING), -1);
}

static void test_bc_detachment_errors_and_view(void **st) {
    (void)st;
    cdem_model m = fx_model(100);
    cdem_error err;
    cdem_bc bc;
    cdem_state s;
    fx_assembly(&s);
    cdem_params p = fx_params(CDEM_MODE_DETACHMENT);
    p.detachment_walls = (cdem_walls_choice)7;
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "detachment_walls = 7"));
    p = fx_params(CDEM_MODE_DETACHMENT);
    p.detachment_walls = CDEM_WALLS_BOTH;
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_OK);
    char *v = fx_view(&bc);
    assert_non_null(strstr(v, "both lateral walls"));
    assert_non_null(strstr(v, "total shortening"));
    free(v);
    cdem_bc_free(&bc);
    /* only a base: no right wall to move */
    cdem_state bare;
    assert_int_equal(cdem_state_init(&bare, 8, 0, &err), CDEM_OK);
    for (int k = 0; k < 5; k++)
        assert_int_equal(
            cdem_state_append(&bare, -1, 100.0 * k, 0, RW, 1, 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &bare, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "no right lateral wall"));
    cdem_state_free(&bare);
    cdem_state_free(&s);
}

/* Both wall choices run through cdem_run on a small default model; the file reports the
 * total shortening (the sum of both walls' displacements for "both", manual v2.6), and the
 * deformation increments are one display interval of boundary (each wall's) displacement
 * apart for both choices: 2 x display interval of shortening for "both". */
static void test_bc_detachment_cdem_run(void **st) {
    (void)st;
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_DETACHMENT;
    p.display_interval = 1.0; /* m: about 50 steps, so 300 steps write 6 increments */
    for (int k = 0; k < 2; k++) {
        p.detachment_walls = k == 0 ? CDEM_WALLS_RIGHT : CDEM_WALLS_BOTH;
        cdem_increment_info last;
        cdem_model m;
        const char *name = k == 0 ? "test_bc_detachment_run_right" : "test_bc_detachment_run_both";
        fx_cdem_run(p, name, 300, &last, &m);
        assert_int_equal(last.step, m.equil_steps + 300);
        const double walls = k == 0 ? 1.0 : 2.0; /* moving walls */
        assert_float_equal(last.net_displacement, walls * 300.0 * m.displacement_per_step, 1e-9);
        char path[1024], file[256];
        snprintf(file, sizeof file, "%s.h5", name); /* the file fx_cdem_run wrote */
        scratch_path(path, sizeof path, file);
        cdem_error err;
        cdem_h5_reader *r = NULL;
        assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
        const size_t n = cdem_h5_reader_increment_count(r);
        int deform = 0;
        double prev = 0.0;
        for (size_t i = 0; i < n; i++) {
            cdem_increment_info inf;
            assert_int_equal(cdem_h5_reader_increment_info(r, i, &inf, &err), CDEM_OK);
            if (inf.step <= m.equil_steps)
                continue;
            /* every full deformation increment adds one display interval of each wall's
             * displacement (to within one step's rounding); the last may be shorter */
            if (inf.step < last.step)
                assert_float_equal(inf.net_displacement - prev, walls * p.display_interval,
                                   walls * m.displacement_per_step);
            assert_float_equal(inf.net_displacement,
                               walls * (double)(inf.step - m.equil_steps) * m.displacement_per_step,
                               1e-9);
            prev = inf.net_displacement;
            deform++;
        }
        assert_int_equal(deform, 6); /* 300 steps / ~50.3 steps per increment, + the last */
        cdem_h5_reader_close(r);
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_detachment_right_wall),
        cmocka_unit_test(test_bc_detachment_both_walls),
        cmocka_unit_test(test_bc_detachment_base_contacts_are_wall_class),
        cmocka_unit_test(test_bc_detachment_errors_and_view),
        cmocka_unit_test(test_bc_detachment_cdem_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
