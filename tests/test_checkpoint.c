/* Tests of checkpoints (solver/base/checkpoint.h and every module's snapshot_put/_get through
 * cdem_run_capture / cdem_run_open with a snapshot): a run of N steps straight and a run
 * captured at step k, freed, restored into a fresh run context and continued to N must hold
 * bit-identical state (every array of the capture: elements, pair list with histories,
 * stepper, boundary mode, sedimentation with its RNG, run counters). Cases: the planar-fault
 * default with bonds (k in equilibration and in deformation), listric CD, biaxial (platens,
 * averaging window, reference), sedimentation with growth strata (k during a settling), plus
 * erosion/overburden, vertical faults, detachment and repose (the irregular fault shares the
 * listric code). Also: refused restores (another parameter set, version text, missing array) with
 * their messages. No file is written (output_path NULL). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "checkpoint.h"
#include "bc.h"
#include "model.h"
#include "run.h"
#include "snapshot.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cdem_params small_params(void) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.width = 10.0;
    p.height = 2.5;
    p.equilibration = 100.0;
    p.runtime = 150.0;
    p.series_interval = 50;
    return p;
}

static cdem_run_options mem_options(void) {
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = NULL; /* in memory: no file */
    o.quiet = 1;
    return o;
}

/* Runs p to step `until` and captures it into snap. */
static void run_to(const cdem_params *p, const cdem_snapshot *from, long until, cdem_snapshot *snap,
                   long *total) {
    cdem_run_options o = mem_options();
    cdem_error err;
    cdem_error_clear(&err);
    cdem_run_ctx *r = NULL;
    if (cdem_run_open(p, &o, from, &r, &err) != CDEM_OK)
        fail_msg("cdem_run_open: %s", err.msg);
    if (total)
        *total = cdem_run_total_steps(r);
    if (cdem_run_advance(r, until, &err) != CDEM_OK)
        fail_msg("cdem_run_advance: %s", err.msg);
    assert_int_equal(cdem_run_current_step(r), until);
    if (cdem_run_capture(r, snap, &err) != CDEM_OK)
        fail_msg("cdem_run_capture: %s", err.msg);
    assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
}

static int64_t snap_i64(const cdem_snapshot *s, const char *name) {
    const cdem_snapshot_array *a = cdem_snapshot_get(s, name);
    assert_non_null(a);
    assert_int_equal(a->type, CDEM_SNAP_I64);
    int64_t v;
    memcpy(&v, a->data, sizeof v);
    return v;
}

/* Straight to n versus k, capture, free, restore, on to n: every array identical. With
 * separate = 0 the straight run is the one captured at k (capturing only reads the state;
 * the separate runs of the first case check that too), which saves k steps. */
static void check_resume_opt(const cdem_params *p, long k, long n, int separate) {
    cdem_snapshot *straight = NULL, *mid = NULL, *resumed = NULL;
    cdem_error err;
    assert_int_equal(cdem_snapshot_alloc(&straight, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_alloc(&mid, &err), CDEM_OK);
    assert_int_equal(cdem_snapshot_alloc(&resumed, &err), CDEM_OK);
    if (separate) {
        long total = 0;
        run_to(p, NULL, n, straight, &total);
        assert_true(n <= total);
        run_to(p, NULL, k, mid, NULL);
    } else {
        cdem_run_options o = mem_options();
        cdem_run_ctx *r = NULL;
        if (cdem_run_open(p, &o, NULL, &r, &err) != CDEM_OK)
            fail_msg("cdem_run_open: %s", err.msg);
        assert_true(n <= cdem_run_total_steps(r));
        assert_int_equal(cdem_run_advance(r, k, &err), CDEM_OK);
        assert_int_equal(cdem_run_capture(r, mid, &err), CDEM_OK);
        assert_int_equal(cdem_run_advance(r, n, &err), CDEM_OK);
        assert_int_equal(cdem_run_current_step(r), n);
        assert_int_equal(cdem_run_capture(r, straight, &err), CDEM_OK);
        assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
    }
    assert_int_equal(snap_i64(mid, "run.step"), k);
    run_to(p, mid, n, resumed, NULL);
    const char *diff = NULL;
    if (!cdem_snapshot_equal(straight, resumed, &diff))
        fail_msg("resumed at step %ld, compared at step %ld: array %s differs", k, n,
                 diff ? diff : "?");
    /* the capture is the complete state: something did happen between k and n */
    assert_int_equal(cdem_snapshot_equal(straight, mid, NULL), 0);
    cdem_snapshot_free(straight);
    cdem_snapshot_free(mid);
    cdem_snapshot_free(resumed);
}

static void check_resume(const cdem_params *p, long k, long n) {
    check_resume_opt(p, k, n, 0);
}

static long model_steps(const cdem_params *p, long *equil) {
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(p, &m, &err), CDEM_OK);
    *equil = m.equil_steps;
    return m.total_steps;
}

static void test_checkpoint_planar_bonded_resume_is_bit_identical(void **st) {
    (void)st;
    cdem_params p = small_params();
    p.material = CDEM_MATERIAL_BONDED;
    p.calculate_stress = 1;
    long equil = 0;
    const long total = model_steps(&p, &equil);
    assert_true(total > equil + 40);
    /* across the end of equilibration (bonds made after the restore); separate runs */
    check_resume_opt(&p, equil - 7, equil + 30, 1);
    /* inside deformation, to the end of the run (final increment, completed) */
    check_resume(&p, equil + 13, total);
}

static void test_checkpoint_planar_granular_erosion_overburden(void **st) {
    (void)st;
    cdem_params p = small_params();
    p.erosion = 1;
    p.erosion_base_level = 1.0;
    p.overburden_pressure = 1e6;
    long equil = 0;
    const long total = model_steps(&p, &equil);
    check_resume(&p, equil + 5, total < equil + 60 ? total : equil + 60);
}

static void test_checkpoint_listric_cd_resume_is_bit_identical(void **st) {
    (void)st;
    cdem_params p = small_params();
    p.mode = CDEM_MODE_LISTRIC_FAULT;
    p.kinematics = CDEM_KIN_CD;
    p.fault_location = 0.35;
    p.fault_dip = 45.0;
    long equil = 0;
    const long total = model_steps(&p, &equil);
    check_resume(&p, equil + 9, total < equil + 50 ? total : equil + 50);
}

static void test_checkpoint_biaxial_resume_is_bit_identical(void **st) {
    (void)st;
    cdem_params p = small_params();
    p.mode = CDEM_MODE_BIAXIAL;
    p.height = 5.0;
    p.confining_pressure = 1e7;
    long equil = 0;
    const long total = model_steps(&p, &equil);
    /* series samples fill the averaging window on both sides of the checkpoint */
    check_resume(&p, equil + 26, total < equil + 120 ? total : equil + 120);
}

static void test_checkpoint_sedimentation_resume_is_bit_identical(void **st) {
    (void)st;
    cdem_params p = small_params();
    p.runtime = 160.0;
    p.display_interval = 0.5;
    p.sedimentation = 1;
    p.sea_level_rise = CDEM_SEA_MID;
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    const long first = m.equil_steps + m.sediment_steps; /* step of the first deposit */
    assert_true(first + m.settling_steps + 10 < m.total_steps);
    /* inside the first settling, on past its end (cohesion of the deposit made after the
     * restore) */
    const long k = first + (m.settling_steps > 2 ? m.settling_steps / 2 : 1);
    long n = first + m.sediment_steps + 3;
    if (n > m.total_steps)
        n = m.total_steps;
    check_resume(&p, k, n);
    /* the deposit after the restore draws the same random numbers */
    check_resume(&p, first - 3, first + 2);
}

/* The other modes, across the start of deformation (repose removes its walls, the others
 * start moving after the restore). */
static void test_checkpoint_other_modes_resume_is_bit_identical(void **st) {
    (void)st;
    const cdem_mode modes[] = {CDEM_MODE_VERTICAL_FAULTS, CDEM_MODE_DETACHMENT, CDEM_MODE_REPOSE};
    for (size_t i = 0; i < sizeof modes / sizeof modes[0]; i++) {
        cdem_params p = small_params();
        p.mode = modes[i];
        long equil = 0;
        model_steps(&p, &equil);
        check_resume(&p, equil - 2, equil + 25);
    }
}

/* A restore into a run of other parameters, another version text or a damaged snapshot is
 * refused with a message naming what differs. */
static void test_checkpoint_refuses_mismatched_restore(void **st) {
    (void)st;
    cdem_params p = small_params();
    cdem_snapshot *snap = NULL;
    cdem_error err;
    assert_int_equal(cdem_snapshot_alloc(&snap, &err), CDEM_OK);
    run_to(&p, NULL, 20, snap, NULL);
    cdem_run_options o = mem_options();
    cdem_run_ctx *r = NULL;

    cdem_params q = p;
    q.element.friction = 0.5;
    assert_int_equal(cdem_run_open(&q, &o, snap, &r, &err), CDEM_ERR_CONFLICT);
    assert_null(r);
    assert_non_null(strstr(err.msg, "parameter set"));
    assert_non_null(strstr(err.msg, "friction"));

    assert_int_equal(cdem_ckpt_put_text(snap, "run", "version", "0.0.0-other", &err), CDEM_OK);
    assert_int_equal(cdem_run_open(&p, &o, snap, &r, &err), CDEM_ERR_VERSION);
    assert_non_null(strstr(err.msg, "0.0.0-other"));

    run_to(&p, NULL, 20, snap, NULL);
    assert_int_equal(cdem_ckpt_put_i64(snap, "run", "layout", 999, &err), CDEM_OK);
    assert_int_equal(cdem_run_open(&p, &o, snap, &r, &err), CDEM_ERR_VERSION);
    assert_non_null(strstr(err.msg, "layout 999"));

    /* a snapshot that lacks an array: the array is named */
    cdem_snapshot *part = NULL;
    assert_int_equal(cdem_snapshot_alloc(&part, &err), CDEM_OK);
    run_to(&p, NULL, 20, snap, NULL);
    for (size_t i = 0; i < cdem_snapshot_count(snap); i++) {
        const cdem_snapshot_array *a = cdem_snapshot_at(snap, i);
        if (strcmp(a->name, "nb.hist") != 0)
            assert_int_equal(cdem_snapshot_put(part, a->name, a->type, a->count, a->data, &err),
                             CDEM_OK);
    }
    assert_int_equal(cdem_run_open(&p, &o, part, &r, &err), CDEM_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "nb.hist"));

    /* a corrupt pair list (pj beyond the elements) */
    run_to(&p, NULL, 20, snap, NULL);
    const cdem_snapshot_array *pj = cdem_snapshot_get(snap, "nb.pj");
    assert_non_null(pj);
    assert_true(pj->count > 0);
    int32_t *bad = malloc(pj->count * sizeof *bad);
    assert_non_null(bad);
    memcpy(bad, pj->data, pj->count * sizeof *bad);
    bad[0] = 1 << 30;
    assert_int_equal(cdem_snapshot_put(snap, "nb.pj", CDEM_SNAP_I32, pj->count, bad, &err),
                     CDEM_OK);
    free(bad);
    assert_int_equal(cdem_run_open(&p, &o, snap, &r, &err), CDEM_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "nb.pi/nb.pj"));

    cdem_snapshot_free(part);
    cdem_snapshot_free(snap);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_checkpoint_planar_bonded_resume_is_bit_identical),
        cmocka_unit_test(test_checkpoint_planar_granular_erosion_overburden),
        cmocka_unit_test(test_checkpoint_listric_cd_resume_is_bit_identical),
        cmocka_unit_test(test_checkpoint_biaxial_resume_is_bit_identical),
        cmocka_unit_test(test_checkpoint_sedimentation_resume_is_bit_identical),
        cmocka_unit_test(test_checkpoint_other_modes_resume_is_bit_identical),
        cmocka_unit_test(test_checkpoint_refuses_mismatched_restore),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
