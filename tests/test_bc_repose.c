/* Tests of solver/bc_repose: at the start of deformation the right wall (or both lateral
 * walls) is removed through the integrator's removal path (ids reported, the rest kept),
 * nothing moves afterwards, net displacement 0; elements beyond the ends of the base or
 * below it are removed by the escape rule and counted; the display interval is in seconds;
 * and an end-to-end cdem_run writes the walls before and not after the first deformation
 * step. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc_fixtures.h"
#include "h5format.h"
#include "bc.h"
#include "model.h"
#include "run.h"
#include "scratch.h"

#include <stdio.h>
#include <stdlib.h>

static long count_lateral(const cdem_state *s, double x) {
    long n = 0;
    for (size_t i = 0; i < s->n; i++)
        n += (s->flags[i] & CDEM_FLAG_WALL) && s->y[i] > 0.0 && s->x[i] == x;
    return n;
}

static long count_base(const cdem_state *s) {
    long n = 0;
    for (size_t i = 0; i < s->n; i++)
        n += (s->flags[i] & CDEM_FLAG_WALL) && s->y[i] == 0.0;
    return n;
}

/* Equilibrates a few steps, begins deformation, checks the removal, runs k more steps. */
static void check_removal(cdem_walls_choice walls) {
    cdem_params p = fx_params(CDEM_MODE_REPOSE);
    p.repose_walls = walls;
    cdem_model m = fx_model(200);
    cdem_error err;
    cdem_state s;
    cdem_bc bc;
    cdem_integrator it;
    fx_assembly(&s);
    /* two elements against each lateral wall (slightly overlapping it: touching during the
     * two equilibration steps below) */
    for (int k = 0; k < 2; k++) {
        const double r = 80.0, y = 1000.0 + 200.0 * k;
        assert_int_equal(
            cdem_state_append(&s, -1, WIDTH - RW - r + 3.0, y, r, fx_mass(r), 1, 0, 0, NULL, &err),
            CDEM_OK);
        assert_int_equal(
            cdem_state_append(&s, -1, RW + r - 3.0, y, r, fx_mass(r), 1, 0, 0, NULL, &err),
            CDEM_OK);
    }
    for (int k = 1; k <= 3; k++) /* three resting on the base (slightly overlapping it) */
        assert_int_equal(cdem_state_append(&s, -1, 1000.0 * k, RW + 80.0 - 3.0, 80.0, fx_mass(80.0),
                                           1, 0, 0, NULL, &err),
                         CDEM_OK);
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    cdem_integrator_enable_escape(&it);
    for (long j = 1; j <= 2; j++) /* equilibration: walls still */
        assert_int_equal(cdem_integrator_step(&it, &s, NULL, 0, 0.0, &err), CDEM_OK);
    const size_t n0 = s.n;
    assert_int_equal(count_lateral(&s, WIDTH), 15);
    assert_int_equal(count_lateral(&s, 0.0), 15);
    /* the right wall's ids, to compare with the reported ones */
    int32_t right_ids[15];
    size_t nr = 0;
    for (size_t i = 0; i < s.n; i++)
        if ((s.flags[i] & CDEM_FLAG_WALL) && s.y[i] > 0.0 && s.x[i] == WIDTH)
            right_ids[nr++] = s.id[i];
    /* cohesive contacts at the end of equilibration: those with a removed wall must go, the
     * others must survive the removal (histories follow the elements) */
    const long made = cdem_integrator_make_cohesive(&it, &s);
    long with_removed = 0;
    for (size_t q = 0; q < it.nb.np; q++) {
        if (!(it.nb.hist[q] & CDEM_PAIR_COHESIVE))
            continue;
        const size_t a = (size_t)it.nb.pi[q], b = (size_t)it.nb.pj[q];
        const int ra = (s.flags[a] & CDEM_FLAG_WALL) && s.y[a] > 0.0 &&
                       (s.x[a] == WIDTH || (walls == CDEM_WALLS_BOTH && s.x[a] == 0.0));
        const int rb = (s.flags[b] & CDEM_FLAG_WALL) && s.y[b] > 0.0 &&
                       (s.x[b] == WIDTH || (walls == CDEM_WALLS_BOTH && s.x[b] == 0.0));
        with_removed += ra || rb;
    }
    assert_int_equal(with_removed, walls == CDEM_WALLS_BOTH ? 4 : 2);
    assert_true(made >= with_removed + 3); /* the three on the base */
    size_t nrem = 0;
    assert_int_equal(cdem_integrator_begin_deformation(&it, &s, &bc, &nrem, &err), CDEM_OK);
    long contacts = 0, cohesive = 0;
    cdem_integrator_count(&it, &contacts, &cohesive);
    assert_int_equal(cohesive, made - with_removed);
    const size_t expect = walls == CDEM_WALLS_BOTH ? 30 : 15;
    assert_int_equal(nrem, expect);
    assert_int_equal(it.removal.n_removed_last, expect);
    assert_int_equal(it.removal.n_removed, 0); /* not counted as escapes */
    assert_int_equal(s.n, n0 - expect);
    assert_int_equal(count_lateral(&s, WIDTH), 0);
    assert_int_equal(count_lateral(&s, 0.0), walls == CDEM_WALLS_BOTH ? 0 : 15);
    assert_int_equal(count_base(&s), 41);
    for (size_t k = 0; k < nr; k++) {
        assert_true(fx_find(&s, right_ids[k]) == SIZE_MAX);
        int found = 0;
        for (size_t q = 0; q < it.removal.n_removed_last; q++)
            found |= it.removal.removed_ids[q] == right_ids[k];
        assert_true(found);
    }
    /* deformation: no boundary moves, net 0 */
    cdem_state before = {0};
    memset(&before, 0, sizeof before);
    assert_int_equal(cdem_state_copy(&before, &s, &err), CDEM_OK);
    for (long j = 1; j <= 100; j++)
        assert_int_equal(cdem_integrator_step(&it, &s, &bc, j, m.displacement_per_step, &err),
                         CDEM_OK);
    for (size_t i = 0; i < before.n; i++)
        if (before.flags[i] & CDEM_FLAGS_BOUNDARY) {
            double dx, dy;
            fx_displacement(&before, &s, before.id[i], &dx, &dy);
            assert_true(dx == 0.0 && dy == 0.0);
        }
    assert_true(cdem_bc_net_displacement(&bc) == 0.0);
    /* a second call removes nothing more */
    assert_int_equal(cdem_integrator_begin_deformation(&it, &s, &bc, &nrem, &err), CDEM_OK);
    assert_int_equal(nrem, 0);
    cdem_state_free(&before);
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
}

static void test_bc_repose_right_wall_removed(void **st) {
    (void)st;
    check_removal(CDEM_WALLS_RIGHT);
}

static void test_bc_repose_both_walls_removed(void **st) {
    (void)st;
    check_removal(CDEM_WALLS_BOTH);
}

/* After the walls are gone, an element beyond the end of the base (by more than its radius)
 * or below the base is removed and counted; one just inside the end stays. */
static void test_bc_repose_escape_beyond_base(void **st) {
    (void)st;
    cdem_params p = fx_params(CDEM_MODE_REPOSE);
    p.repose_walls = CDEM_WALLS_BOTH;
    cdem_model m = fx_model(200);
    cdem_error err;
    cdem_state s;
    cdem_bc bc;
    cdem_integrator it;
    fx_assembly(&s);
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    cdem_integrator_enable_escape(&it);
    size_t nrem = 0;
    assert_int_equal(cdem_integrator_begin_deformation(&it, &s, &bc, &nrem, &err), CDEM_OK);
    assert_int_equal(nrem, 30);
    const double r = 60.0;
    const int32_t id_right = s.next_id;
    assert_int_equal(
        cdem_state_append(&s, -1, WIDTH + r + 20.0, 300.0, r, fx_mass(r), 1, 0, 0, NULL, &err),
        CDEM_OK);
    const int32_t id_left = s.next_id;
    assert_int_equal(
        cdem_state_append(&s, -1, -r - 20.0, 300.0, r, fx_mass(r), 1, 0, 0, NULL, &err), CDEM_OK);
    const int32_t id_below = s.next_id;
    assert_int_equal(cdem_state_append(&s, -1, 2000.0, -200.0, r, fx_mass(r), 1, 0, 0, NULL, &err),
                     CDEM_OK);
    const int32_t id_inside = s.next_id; /* on the last base element, within one radius */
    assert_int_equal(
        cdem_state_append(&s, -1, WIDTH + 0.5 * r, RW + r, r, fx_mass(r), 1, 0, 0, NULL, &err),
        CDEM_OK);
    const size_t n0 = s.n;
    assert_int_equal(cdem_integrator_step(&it, &s, &bc, 1, m.displacement_per_step, &err), CDEM_OK);
    assert_int_equal(it.removal.n_removed, 3);
    assert_int_equal(it.removal.n_removed_last, 3);
    assert_int_equal(s.n, n0 - 3);
    assert_true(fx_find(&s, id_right) == SIZE_MAX);
    assert_true(fx_find(&s, id_left) == SIZE_MAX);
    assert_true(fx_find(&s, id_below) == SIZE_MAX);
    assert_true(fx_find(&s, id_inside) != SIZE_MAX);
    assert_float_equal(it.removal.escape_xmin, 0.0, 1e-12); /* the base ends */
    assert_float_equal(it.removal.escape_xmax, WIDTH, 1e-12);
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
}

/* The walls to remove are told apart by the assembly's middle, not by the middle of the
 * walls' extent: with the base extended far past the right wall (as assembly.c builds it
 * for this mode), the right wall is still the one removed and the base stays whole. */
static void test_bc_repose_extended_base_keeps_right_wall_choice(void **st) {
    (void)st;
    cdem_params p = fx_params(CDEM_MODE_REPOSE);
    p.repose_walls = CDEM_WALLS_RIGHT;
    cdem_model m = fx_model(200);
    cdem_error err;
    cdem_state s;
    cdem_bc bc;
    cdem_integrator it;
    fx_assembly(&s);
    for (int k = 1; k <= 60; k++) /* 6 km of base beyond the right wall */
        assert_int_equal(cdem_state_append(&s, -1, WIDTH + 2.0 * RW * k, 0.0, RW, fx_mass(RW), 0,
                                           CDEM_FLAG_WALL, 0, NULL, &err),
                         CDEM_OK);
    assert_int_equal(cdem_bc_init(&bc, &p, &m, &s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    cdem_integrator_enable_escape(&it);
    size_t nrem = 0;
    assert_int_equal(cdem_integrator_begin_deformation(&it, &s, &bc, &nrem, &err), CDEM_OK);
    assert_int_equal(nrem, 15);
    assert_int_equal(count_lateral(&s, WIDTH), 0);
    assert_int_equal(count_lateral(&s, 0.0), 15);
    assert_int_equal(count_base(&s), 41 + 60);
    assert_int_equal(cdem_integrator_step(&it, &s, &bc, 1, m.displacement_per_step, &err), CDEM_OK);
    assert_float_equal(it.removal.escape_xmax, WIDTH + 2.0 * RW * 60, 1e-9); /* its end */
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
    cdem_state_free(&s);
}

/* For repose the display interval is seconds: increments are display_interval apart in time;
 * for the other modes it is metres of boundary displacement. */
static void test_bc_repose_display_interval_seconds(void **st) {
    (void)st;
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = CDEM_MODE_REPOSE;
    p.display_interval = 7.0;
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    for (int k = m.n_increments_equil; k < m.n_increments_total - 1; k++) {
        const long a = cdem_model_increment_step(&m, k), b = cdem_model_increment_step(&m, k + 1);
        assert_float_equal((double)(b - a) * m.dt, 7.0, 1.01 * m.dt); /* steps are rounded */
    }
    p.mode = CDEM_MODE_DETACHMENT;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    const int k = m.n_increments_equil;
    const long a = cdem_model_increment_step(&m, k), b = cdem_model_increment_step(&m, k + 1);
    assert_float_equal((double)(b - a) * m.displacement_per_step, 7.0,
                       0.51 * m.displacement_per_step);
}

/* End to end: a small repose model through cdem_run, stopped a little after equilibration. */
static void test_bc_repose_run_removes_walls(void **st) {
    (void)st;
    char path[1024];
    scratch_path(path, sizeof path, "test_bc_repose_run.h5");
    cdem_params p;
    cdem_params_defaults(&p);
    p.width = 10.0;
    p.height = 2.5;
    p.equilibration = 60.0;
    p.runtime = 100.0;
    p.mode = CDEM_MODE_REPOSE;
    p.repose_walls = CDEM_WALLS_RIGHT;
    p.display_interval = 10.0; /* s */
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    char *logbuf = NULL;
    size_t loglen = 0;
    FILE *log = open_memstream(&logbuf, &loglen);
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.log = log;
    o.max_steps = m.equil_steps + (long)ceil(20.0 / m.dt) + 1; /* 20 s of collapse */
    cdem_status stt = cdem_run(&p, &o, &err);
    fclose(log);
    if (stt != CDEM_OK)
        fail_msg("cdem_run: %s", err.msg);
    assert_non_null(strstr(logbuf, "start of deformation"));
    assert_non_null(strstr(logbuf, "removed by the repose mode"));
    free(logbuf);
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    const size_t ninc = cdem_h5_reader_increment_count(r);
    const size_t ke = (size_t)m.n_increments_equil;
    assert_true(ninc >= ke + 3);
    cdem_increment_info ie, i1, i2;
    assert_int_equal(cdem_h5_reader_increment_info(r, ke, &ie, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_increment_info(r, ke + 1, &i1, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_increment_info(r, ke + 2, &i2, &err), CDEM_OK);
    assert_int_equal(ie.step, m.equil_steps);
    /* the right wall: the wall elements right of the middle above the base */
    cdem_state s;
    assert_int_equal(cdem_state_init(&s, 16, 0, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_load_increment(r, ke, &s, &ie, &err), CDEM_OK);
    double ymin = INFINITY, xmin = INFINITY, xmax = -INFINITY;
    for (size_t i = 0; i < s.n; i++)
        if (s.flags[i] & CDEM_FLAG_WALL) {
            ymin = fmin(ymin, s.y[i]);
            xmin = fmin(xmin, s.x[i]);
            xmax = fmax(xmax, s.x[i]);
        }
    /* the base runs on past the right wall by the assembly's width */
    assert_true(xmax >= 2.0 * m.width_m + m.radius[0] * (1 - 1e-9));
    assert_true(xmin == -m.radius[0]);
    long right = 0;
    for (size_t i = 0; i < s.n; i++)
        right += (s.flags[i] & CDEM_FLAG_WALL) && s.y[i] > ymin + 0.5 * m.radius[0] &&
                 s.x[i] > 0.5 * (xmin + xmax);
    assert_true(right > 10);
    assert_int_equal(cdem_h5_reader_load_increment(r, ke + 1, &s, &i1, &err), CDEM_OK);
    long right_after = 0, walls_after = 0;
    for (size_t i = 0; i < s.n; i++) {
        walls_after += (s.flags[i] & CDEM_FLAG_WALL) != 0;
        right_after += (s.flags[i] & CDEM_FLAG_WALL) && s.y[i] > ymin + 0.5 * m.radius[0] &&
                       s.x[i] > 0.5 * (xmin + xmax);
    }
    assert_int_equal(right_after, 0);
    assert_true(walls_after > 0);
    assert_true(i1.n_elements <= ie.n_elements - right);
    /* increments 10 s apart; net displacement 0 */
    assert_float_equal(i2.time - i1.time, 10.0, 0.51 * m.dt);
    assert_true(i1.net_displacement == 0.0 && i2.net_displacement == 0.0);
    cdem_state_free(&s);
    cdem_h5_reader_close(r);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_repose_right_wall_removed),
        cmocka_unit_test(test_bc_repose_both_walls_removed),
        cmocka_unit_test(test_bc_repose_escape_beyond_base),
        cmocka_unit_test(test_bc_repose_extended_base_keeps_right_wall_choice),
        cmocka_unit_test(test_bc_repose_display_interval_seconds),
        cmocka_unit_test(test_bc_repose_run_removes_walls),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
