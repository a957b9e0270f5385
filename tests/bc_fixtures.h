/* bc_fixtures: a hand-made model and assembly shared by the boundary-mode tests
 * (test_bc_vertical, test_bc_detachment, test_bc_repose): a base of wall elements at
 * y = 0 from x = 0 to WIDTH, lateral walls at x = 0 and x = WIDTH above it, and 4 rows of
 * free elements; helpers to run k deformation steps and to find an element's displacement
 * by id (the state may be re-sorted). Header-only, static functions, test code only. */
#ifndef CDEM_TESTS_BC_FIXTURES_H
#define CDEM_TESTS_BC_FIXTURES_H

#include "bc.h"
#include "h5format.h"
#include "integrate.h"
#include "run.h"
#include "scratch.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define KN    1.544871985e9
#define RHO   2500.0
#define DT    0.028
#define WIDTH 4000.0
#define RW    50.0
#define DPS   (CDEM_BOUNDARY_ACCEL * DT * DT) /* m, displacement per deformation step */

__attribute__((unused)) static double fx_rnd(uint64_t *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * (1.0 / 9007199254740992.0);
}

__attribute__((unused)) static double fx_mass(double r) {
    return RHO * M_PI * r * r;
}

__attribute__((unused)) static cdem_model fx_model(long def_steps) {
    cdem_model m;
    memset(&m, 0, sizeof m);
    const double r[4] = {50.0, 75.0, 100.0, 125.0};
    for (int k = 0; k < 4; k++) {
        m.radius[k] = r[k];
        m.mass[k] = fx_mass(r[k]);
    }
    m.min_mass = m.mass[0];
    m.max_radius = 125.0;
    m.kn = m.ks = KN;
    m.dt = DT;
    m.damping = DT * 3.0e9;
    m.gravity = 9.81;
    m.boundary_speed = CDEM_BOUNDARY_ACCEL * DT;
    m.displacement_per_step = m.boundary_speed * DT;
    m.width_m = WIDTH;
    m.height_m = 1000.0;
    m.equil_steps = 0;
    m.total_steps = def_steps;
    m.total_displacement = (double)def_steps * m.displacement_per_step;
    return m;
}

__attribute__((unused)) static cdem_params fx_params(cdem_mode mode) {
    cdem_params p;
    memset(&p, 0, sizeof p);
    p.material = CDEM_MATERIAL_GRANULAR;
    p.density = RHO;
    p.element = (cdem_contact_material){.friction = 0.25, .cohesion = 5e9, .breaking_strain = 0.1};
    p.wall = p.element;
    p.fault = p.element;
    p.mode = mode;
    p.vertical_fault_location = 0.35;
    p.vertical_fault_spacing = 0.3;
    p.vertical_sense = CDEM_VERT_CALDERA;
    p.detachment_walls = CDEM_WALLS_RIGHT;
    p.repose_walls = CDEM_WALLS_RIGHT;
    return p;
}

/* Base (y = 0, x = 0 .. WIDTH), lateral walls at x = 0 and WIDTH (y = 100 .. 1500), and 4
 * rows of free elements above the base. */
__attribute__((unused)) static void fx_assembly(cdem_state *s) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, 256, 0, &err), CDEM_OK);
    for (double x = 0.0; x <= WIDTH + 1e-9; x += 2.0 * RW)
        assert_int_equal(
            cdem_state_append(s, -1, x, 0.0, RW, fx_mass(RW), 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
    for (double y = 2.0 * RW; y <= 1500.0; y += 2.0 * RW) {
        assert_int_equal(
            cdem_state_append(s, -1, 0.0, y, RW, fx_mass(RW), 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
        assert_int_equal(
            cdem_state_append(s, -1, WIDTH, y, RW, fx_mass(RW), 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
    }
    uint64_t g = 5;
    for (int j = 0; j < 4; j++)
        for (double x = 150.0 + (j % 2) * 100.0; x < WIDTH - 100.0; x += 200.0) {
            double r = 99.0 - 4.0 * fx_rnd(&g);
            assert_int_equal(
                cdem_state_append(s, -1, x, 150.0 + j * 173.2, r, fx_mass(r), 1, 0, 0, NULL, &err),
                CDEM_OK);
        }
}

/* Index of element id in s, or SIZE_MAX. */
__attribute__((unused)) static size_t fx_find(const cdem_state *s, int32_t id) {
    for (size_t i = 0; i < s->n; i++)
        if (s->id[i] == id)
            return i;
    return SIZE_MAX;
}

/* Displacement of element id between s0 and s. */
__attribute__((unused)) static void fx_displacement(const cdem_state *s0, const cdem_state *s,
                                                    int32_t id, double *dx, double *dy) {
    const size_t a = fx_find(s0, id), b = fx_find(s, id);
    assert_true(a != SIZE_MAX && b != SIZE_MAX);
    *dx = s->x[b] - s0->x[a];
    *dy = s->y[b] - s0->y[a];
}

typedef struct {
    cdem_state s0;  /* state after the mode's init */
    cdem_state s;   /* state after the steps */
    double net_mid; /* net displacement after half the steps */
    double net_end; /* net displacement at the end */
    long removed;   /* escaped elements removed */
} fx_result;

/* Initialises mode p on the fixture assembly and runs k deformation steps. */
__attribute__((unused)) static void fx_run(cdem_params p, long k, fx_result *out) {
    cdem_model m = fx_model(k);
    cdem_error err;
    cdem_bc bc;
    cdem_integrator it;
    memset(out, 0, sizeof *out);
    fx_assembly(&out->s);
    if (cdem_bc_init(&bc, &p, &m, &out->s, &err) != CDEM_OK)
        fail_msg("cdem_bc_init: %s", err.msg);
    assert_int_equal(cdem_state_copy(&out->s0, &out->s, &err), CDEM_OK);
    assert_int_equal(cdem_integrator_init(&it, &p, &m, &err), CDEM_OK);
    cdem_integrator_enable_escape(&it);
    size_t nrem = 0;
    assert_int_equal(cdem_integrator_begin_deformation(&it, &out->s, &bc, &nrem, &err), CDEM_OK);
    for (long j = 1; j <= k; j++) {
        assert_int_equal(cdem_integrator_step(&it, &out->s, &bc, j, m.displacement_per_step, &err),
                         CDEM_OK);
        if (j == k / 2)
            out->net_mid = cdem_bc_net_displacement(&bc);
    }
    out->removed = it.removal.n_removed;
    out->net_end = cdem_bc_net_displacement(&bc);
    cdem_integrator_free(&it);
    cdem_bc_free(&bc);
}

__attribute__((unused)) static void fx_result_free(fx_result *r) {
    cdem_state_free(&r->s0);
    cdem_state_free(&r->s);
}

/* The view text of an initialised mode (malloc'd). */
__attribute__((unused)) static char *fx_view(const cdem_bc *bc) {
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    assert_non_null(f);
    cdem_bc_view(bc, f);
    fclose(f);
    return buf;
}

/* Opens the run file fx_cdem_run wrote for `name` (in the scratch folder). */
__attribute__((unused)) static cdem_h5_reader *fx_open_run(const char *name) {
    char path[1024], file[256];
    snprintf(file, sizeof file, "%s.h5", name);
    scratch_path(path, sizeof path, file);
    cdem_error err;
    cdem_h5_reader *r = NULL;
    if (cdem_h5_reader_open(path, &r, &err) != CDEM_OK)
        fail_msg("%s: %s", path, err.msg);
    return r;
}

/* Runs a small default-based model of mode p (10 x 2.5 units, 60 s equilibration) through
 * cdem_run, stopped `def_steps` deformation steps after equilibration; returns the info of
 * the last increment written and the model. */
__attribute__((unused)) static void fx_cdem_run(cdem_params p, const char *name, long def_steps,
                                                cdem_increment_info *last, cdem_model *m) {
    char path[1024], file[256];
    snprintf(file, sizeof file, "%s.h5", name);
    scratch_path(path, sizeof path, file);
    p.width = 10.0;
    p.height = 2.5;
    p.equilibration = 60.0;
    p.runtime = 100.0;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, m, &err), CDEM_OK);
    cdem_run_options o;
    memset(&o, 0, sizeof o);
    o.output_path = path;
    o.quiet = 1;
    o.max_steps = m->equil_steps + def_steps;
    if (cdem_run(&p, &o, &err) != CDEM_OK)
        fail_msg("cdem_run: %s", err.msg);
    cdem_h5_reader *r = fx_open_run(name);
    const size_t n = cdem_h5_reader_increment_count(r);
    assert_true(n > 1);
    assert_int_equal(cdem_h5_reader_increment_info(r, n - 1, last, &err), CDEM_OK);
    assert_string_equal(cdem_h5_reader_stop_reason(r), "stopped-early");
    cdem_h5_reader_close(r);
}

#endif
