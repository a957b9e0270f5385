/* Regression tests of the material at reduced size (docs/solver.md, section 1): with the
 * default material an extensional run opens no void and a collapse leaves no standing cliff;
 * the material of version 0.1 (granular_law = coulomb, cohesive_contacts = equilibrated,
 * settling_friction = 1) does both, which shows that the measures can fail.
 *   - extension: the paper's Fig. 7A set-up (30 degree planar normal fault, first slip off)
 *     on a 10 x 2.5 km assembly at default radii, 400 s of equilibration and 600 s (about
 *     420 m) of slip: no void (analysis/measure/voids.h) and no surface steeper than 40 degrees
 * over 1 km (a graben's flanks); version 0.1's material: a cavity or a chasm.
 *   - collapse: the repose test (right wall removed) on the default 10 x 5 km assembly,
 *     2000 s after the wall goes: a slope of 20-40 degrees is fitted (analysis/measure/repose.h)
 * and nothing is steeper than 60 degrees over 1 km; version 0.1's material: a standing cliff. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "assert_near.h"
#include "h5format.h"
#include "repose.h"
#include "run.h"
#include "voids.h"
#include "scratch.h"

/* Runs p into path and loads its last increment into s. */
static void run_last(const cdem_params *p, const char *name, cdem_state *s) {
    char path[1024];
    scratch_path(path, sizeof path, name);
    remove(path);
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    cdem_error err;
    if (cdem_run(p, &o, &err) != CDEM_OK)
        fail_msg("cdem_run %s: %s", name, err.msg);
    cdem_h5_reader *r = NULL;
    assert_int_equal(cdem_h5_reader_open(path, &r, &err), CDEM_OK);
    size_t idx = 0;
    cdem_increment_info info;
    assert_int_equal(cdem_h5_reader_find_increment(r, "last", &idx, &err), CDEM_OK);
    assert_int_equal(cdem_h5_reader_load_increment(r, idx, s, &info, &err), CDEM_OK);
    cdem_h5_reader_close(r);
    remove(path);
    char xmf[1040];
    snprintf(xmf, sizeof xmf, "%.1000s", path);
    char *dot = strrchr(xmf, '.');
    if (dot) {
        strcpy(dot, ".xmf");
        remove(xmf);
    }
}

/* The material of version 0.1: a Mohr-Coulomb contact with C0 on every contact of the
 * equilibrated assembly, settled with friction. */
static void old_material(cdem_params *p) {
    p->granular_law = CDEM_LAW_COULOMB;
    p->cohesive_contacts = CDEM_COHESIVE_EQUILIBRATED;
    p->settling_friction = 1.0;
}

static cdem_params small_params(cdem_mode mode) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = mode;
    p.height = 2.5;
    p.equilibration = 400.0;
    p.runtime = 1000.0;
    p.display_interval = 100.0;
    return p;
}

static void test_material_extension_opens_no_void(void **st) {
    (void)st;
    cdem_params p = small_params(CDEM_MODE_PLANAR_FAULT);
    p.first_slip = 0; /* extension (paper Fig. 7A) */
    cdem_state s = {0};
    cdem_voids_result v;
    cdem_error err;
    run_last(&p, "test_material_extension.h5", &s);
    assert_int_equal(cdem_voids_measure(&s, 1000.0, &v, &err), CDEM_OK);
    print_message("default material: %zu voids, steepest slope %.1f deg\n", v.n_voids,
                  v.steepest_deg);
    assert_int_equal(v.n_voids, 0);
    assert_true(v.steepest_deg < 40.0);
    cdem_state_free(&s);

    old_material(&p);
    run_last(&p, "test_material_extension_old.h5", &s);
    assert_int_equal(cdem_voids_measure(&s, 1000.0, &v, &err), CDEM_OK);
    print_message("version 0.1's material: %zu voids, steepest slope %.1f deg\n", v.n_voids,
                  v.steepest_deg);
    assert_true(v.n_voids > 0 || v.steepest_deg > 45.0);
    cdem_state_free(&s);
}

static void test_material_collapse_leaves_no_cliff(void **st) {
    (void)st;
    cdem_params p = small_params(CDEM_MODE_REPOSE);
    p.height = 5.0; /* a 2.5 km block of the dense default material stands steeper */
    p.runtime = 2400.0;
    p.display_interval = 200.0;
    cdem_state s = {0};
    cdem_voids_result v;
    cdem_repose_result rep;
    cdem_error err;
    run_last(&p, "test_material_collapse.h5", &s);
    assert_int_equal(cdem_voids_measure(&s, 1000.0, &v, &err), CDEM_OK);
    assert_int_equal(cdem_repose_measure(&s, &rep, &err), CDEM_OK);
    print_message("default material: repose %.1f deg, steepest slope %.1f deg\n", rep.angle_deg,
                  v.steepest_deg);
    assert_true(rep.angle_deg > 20.0 && rep.angle_deg < 40.0);
    assert_true(v.steepest_deg < 60.0);
    assert_int_equal(v.n_voids, 0);
    cdem_state_free(&s);

    old_material(&p);
    run_last(&p, "test_material_collapse_old.h5", &s);
    assert_int_equal(cdem_voids_measure(&s, 1000.0, &v, &err), CDEM_OK);
    const cdem_status st_rep = cdem_repose_measure(&s, &rep, &err);
    print_message("version 0.1's material: repose %s %.1f deg, steepest slope %.1f deg\n",
                  st_rep == CDEM_OK ? "fitted" : "not fitted", rep.angle_deg, v.steepest_deg);
    assert_true(v.steepest_deg > 60.0);
    cdem_state_free(&s);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_material_extension_opens_no_void),
        cmocka_unit_test(test_material_collapse_leaves_no_cliff),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
