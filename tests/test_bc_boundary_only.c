/* The boundary modes' `boundary_only` promise (solver/modes/bc.h), on which the stepper relies to
 * apply a mode before the drift and drift inside the force pass's parallel region
 * (solver/step/integrate.c): a mode that makes it
 *   - writes no free element: every free element's fields are bit-unchanged by its apply;
 *   - reads no free element: its moves of the boundary elements and its net displacement
 *     are bit-identical whatever the free elements' positions, velocities and forces.
 * Checked for every registered mode that makes the promise (each with its variants: both
 * kinematics of the listric and irregular faults, reverse with inversion, both detachment
 * walls), over deformation steps before and after an inversion, on the fixture assembly of
 * the other boundary-mode tests. The biaxial mode, whose servo reads the free elements'
 * extent, must not make it; and an equilibration step of a mode that does not move then is
 * boundary-only whatever the flag. A mode split in step_begin and step_move (the stepper runs
 * the moves over each thread's ranges) gives with its ranges in any order the bits of its
 * apply. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc_fixtures.h"

#include <stdio.h>
#include <stdlib.h>

#define STEPS 30 /* deformation steps applied (inversion, when set, at 40 %) */

static int is_free(const cdem_state *s, size_t i) {
    return !(s->flags[i] & CDEM_FLAGS_BOUNDARY);
}

/* Every field of element i of a and b bit-identical (the same element index). */
static int same_element(const cdem_state *a, const cdem_state *b, size_t i) {
    return a->id[i] == b->id[i] && a->flags[i] == b->flags[i] &&
           memcmp(&a->x[i], &b->x[i], sizeof(double)) == 0 &&
           memcmp(&a->y[i], &b->y[i], sizeof(double)) == 0 &&
           memcmp(&a->vx[i], &b->vx[i], sizeof(double)) == 0 &&
           memcmp(&a->vy[i], &b->vy[i], sizeof(double)) == 0 &&
           memcmp(&a->fx[i], &b->fx[i], sizeof(double)) == 0 &&
           memcmp(&a->fy[i], &b->fy[i], sizeof(double)) == 0;
}

/* The mode's variant `v` (0, 1, ...) as parameters, or 0 when it has no such variant. */
static int variant(cdem_mode mode, int v, cdem_params *p) {
    *p = fx_params(mode);
    p->fault_location = 0.35;
    p->fault_dip = 45.0;
    p->fault_sense = CDEM_SENSE_NORMAL;
    p->kinematics = CDEM_KIN_CH;
    if (mode == CDEM_MODE_IRREGULAR_FAULT) {
        const char *d = getenv("CDEM_TEST_DATA");
        snprintf(p->fault_file, sizeof p->fault_file, "%s/fault_irregular.txt",
                 d && *d ? d : "tests/data");
    }
    switch (v) {
    case 0:
        return 1;
    case 1: /* reverse, inverted during the steps */
        p->fault_sense = CDEM_SENSE_REVERSE;
        p->vertical_sense = CDEM_VERT_PISTON;
        p->inversion = 1;
        p->inversion_percent = 40.0;
        p->detachment_walls = CDEM_WALLS_BOTH;
        return 1;
    case 2: /* the listric and irregular faults' constant displacement (mylar sheet) */
        if (mode != CDEM_MODE_LISTRIC_FAULT && mode != CDEM_MODE_IRREGULAR_FAULT)
            return 0;
        p->kinematics = CDEM_KIN_CD;
        p->inversion = 1;
        p->inversion_percent = 40.0;
        return 1;
    default:
        return 0;
    }
}

/* Scrambles every free element's fields (deterministically): what a boundary-only mode must
 * neither read nor write. */
static void scramble_free(cdem_state *s) {
    uint64_t g = 11;
    for (size_t i = 0; i < s->n; i++) {
        if (!is_free(s, i))
            continue;
        s->x[i] += 40.0 * (fx_rnd(&g) - 0.5);
        s->y[i] += 40.0 * (fx_rnd(&g) - 0.5);
        s->vx[i] = 3.0 * (fx_rnd(&g) - 0.5);
        s->vy[i] = 3.0 * (fx_rnd(&g) - 0.5);
        s->fx[i] = 1e9 * (fx_rnd(&g) - 0.5);
        s->fy[i] = 1e9 * (fx_rnd(&g) - 0.5);
    }
}

/* One variant of a boundary-only mode: two identical initialisations, one with its free
 * elements scrambled; STEPS applies on each. */
static void check_variant(cdem_mode mode, const cdem_params *p) {
    cdem_model m = fx_model(STEPS);
    cdem_error err;
    cdem_state a, b, a0, b0, c;
    cdem_bc bca, bcb, bcc;
    fx_assembly(&a);
    fx_assembly(&b);
    fx_assembly(&c);
    if (cdem_bc_init(&bca, p, &m, &a, &err) != CDEM_OK)
        fail_msg("%s: cdem_bc_init: %s", cdem_mode_name(mode), err.msg);
    assert_int_equal(cdem_bc_init(&bcb, p, &m, &b, &err), CDEM_OK);
    assert_int_equal(cdem_bc_init(&bcc, p, &m, &c, &err), CDEM_OK);
    assert_int_equal(a.n, b.n);
    scramble_free(&b);
    assert_int_equal(cdem_state_copy(&a0, &a, &err), CDEM_OK);
    assert_int_equal(cdem_state_copy(&b0, &b, &err), CDEM_OK);
    /* a mode that moves in equilibration: equilibration steps (k = 0) first */
    for (long k = 0; k < 3 && bca.ops->moves_in_equilibration; k++) {
        assert_true(cdem_bc_apply_is_boundary_only(&bca, 0));
        assert_int_equal(cdem_bc_apply(&bca, &a, 0, m.displacement_per_step, DT, &err), CDEM_OK);
        assert_int_equal(cdem_bc_apply(&bcb, &b, 0, m.displacement_per_step, DT, &err), CDEM_OK);
    }
    for (long k = 1; k <= STEPS; k++) {
        assert_true(cdem_bc_apply_is_boundary_only(&bca, k));
        assert_int_equal(cdem_bc_apply(&bca, &a, k, m.displacement_per_step, DT, &err), CDEM_OK);
        assert_int_equal(cdem_bc_apply(&bcb, &b, k, m.displacement_per_step, DT, &err), CDEM_OK);
        /* a split mode: its moves over three ranges, last range first */
        const cdem_bc_move_fn move = cdem_bc_step_move_of(&bcc, k);
        if (move) {
            assert_int_equal(cdem_bc_step_begin(&bcc, k, m.displacement_per_step, DT, &err),
                             CDEM_OK);
            const long n = (long)c.n, cut[4] = {0, n / 3, (2 * n) / 3, n};
            for (int r = 2; r >= 0; r--)
                move(bcc.ctx, &c, cut[r], cut[r + 1]);
        } else {
            assert_int_equal(cdem_bc_apply(&bcc, &c, k, m.displacement_per_step, DT, &err),
                             CDEM_OK);
        }
    }
    /* the modes whose moves the stepper threads are split (repose moves nothing) */
    if (mode != CDEM_MODE_REPOSE)
        assert_non_null(cdem_bc_step_move_of(&bcc, 1));
    for (size_t i = 0; i < a.n; i++)
        if (!same_element(&a, &c, i))
            fail_msg("%s: element id %d differs between apply and the split moves",
                     cdem_mode_name(mode), (int)a.id[i]);
    const double nc = cdem_bc_net_displacement(&bcc), na0 = cdem_bc_net_displacement(&bca);
    assert_memory_equal(&nc, &na0, sizeof nc);
    size_t moved = 0;
    for (size_t i = 0; i < a.n; i++) {
        if (is_free(&a, i)) {
            if (!same_element(&a, &a0, i) || !same_element(&b, &b0, i))
                fail_msg("%s: apply changed free element id %d", cdem_mode_name(mode),
                         (int)a.id[i]);
            continue;
        }
        /* a boundary element: the same whatever the free elements are */
        if (!same_element(&a, &b, i))
            fail_msg("%s: boundary element id %d moved differently with other free elements",
                     cdem_mode_name(mode), (int)a.id[i]);
        moved += !same_element(&a, &a0, i);
    }
    /* the check is not empty: the mode moved something (repose moves nothing by design) */
    if (mode != CDEM_MODE_REPOSE)
        assert_true(moved > 0);
    const double na = cdem_bc_net_displacement(&bca), nb = cdem_bc_net_displacement(&bcb);
    assert_memory_equal(&na, &nb, sizeof na);
    cdem_state_free(&a);
    cdem_state_free(&b);
    cdem_state_free(&a0);
    cdem_state_free(&b0);
    cdem_state_free(&c);
    cdem_bc_free(&bca);
    cdem_bc_free(&bcb);
    cdem_bc_free(&bcc);
}

static void test_bc_boundary_only_modes_keep_their_promise(void **st) {
    (void)st;
    int checked = 0;
    for (int mi = CDEM_MODE_PLANAR_FAULT; mi <= CDEM_MODE_BIAXIAL; mi++) {
        const cdem_mode mode = (cdem_mode)mi;
        const cdem_bc_ops *ops = NULL;
        cdem_error err;
        assert_int_equal(cdem_bc_find(mode, &ops, &err), CDEM_OK);
        if (!ops->boundary_only)
            continue;
        cdem_params p;
        for (int v = 0; variant(mode, v, &p); v++) {
            check_variant(mode, &p);
            checked++;
        }
    }
    /* planar, listric x3, irregular x3, vertical, detachment, repose: 2 variants or more */
    assert_true(checked >= 13);
}

/* The biaxial servo reads the free elements' extent: it must keep apply after the drift. An
 * equilibration step of a mode that does not move then is boundary-only (nothing happens). */
static void test_bc_boundary_only_flags(void **st) {
    (void)st;
    const cdem_bc_ops *ops = NULL;
    cdem_error err;
    assert_int_equal(cdem_bc_find(CDEM_MODE_BIAXIAL, &ops, &err), CDEM_OK);
    assert_int_equal(ops->boundary_only, 0);
    cdem_bc biaxial = {.ops = ops};
    assert_false(cdem_bc_apply_is_boundary_only(&biaxial, 0));
    assert_false(cdem_bc_apply_is_boundary_only(&biaxial, 5));
    /* a mode without the promise that does not move in equilibration: only k <= 0 */
    const cdem_bc_ops quiet = {.moves_in_equilibration = 0, .boundary_only = 0};
    cdem_bc q = {.ops = &quiet};
    assert_true(cdem_bc_apply_is_boundary_only(&q, 0));
    assert_false(cdem_bc_apply_is_boundary_only(&q, 1));
    assert_false(cdem_bc_apply_is_boundary_only(NULL, 1));
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bc_boundary_only_modes_keep_their_promise),
        cmocka_unit_test(test_bc_boundary_only_flags),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
