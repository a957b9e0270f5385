/* The regional tilt (solver/tilt/, issue 47 item 3): the whole model rotates rigidly relative to
 * gravity, gravity turning in the model's frame, by [tilt] angle over [tilt] onset and
 * duration of deformation time. The runs use the tests' still mode (nothing moves: the tilt
 * alone) at small sizes, in memory.
 *   tilt-1 parameters: off by default (no process, no [tilt] in a run's parameter record);
 *          beyond 45 degrees refused naming [tilt] angle, the value and 45; a window past the
 *          runtime and the surface processes a tilt would make wrong refused naming the keys.
 *   tilt-2 statics: at rest after the tilt, the walls carry the weight along the tilted
 *          vertical (the sum of the forces on the wall elements points the tilt's angle from
 *          -y, and equals the free elements' weight less the drag).
 *   tilt-3 rigid cover: a bonded cover, stiff against its weight, tilted 10 degrees deforms
 *          less than 3 % of the same cover with free-slip contacts (no friction, no cohesion;
 *          measured 1.9 %, the target 1 %: docs/solver.md, "Regional tilt"):
 *          the internal strain the tilt makes is the median residual of the elements'
 *          displacements (tilted run against the same run untilted) after the best-fitting
 *          rigid motion, over the cover's height.
 *   tilt-4 resume: a run resumed from a checkpoint taken mid-tilt ends bit-identical to the
 *          uninterrupted one, gravity mid-way at the scheduled angle.
 *   tilt-5 summary: the summary states the tilt's history; the schedule's angles. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "process.h"
#include "run.h"
#include "run_fixtures.h"
#include "snapshot.h"
#include "state.h"
#include "summary.h"
#include "tilt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The tests' tilting mode (solver/modes/bc_test_tilt.c): gravity tilted 2 degrees from the
 * start, turned 1 degree more over the deformation; its walls never move. */
#define MODE_TILT_START 2.0
#define MODE_TILT_TURN  1.0

/* A small model tilted `angle` degrees over `duration` s from the start of deformation (no
 * file, no checkpoints written), in the default mode (a planar fault). */
static cdem_params tilt_params(double angle, double duration) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.height = 2.5;
    p.equilibration = 200;
    p.runtime = 300;
    p.checkpoint_interval = 0;
    p.tilt_angle = angle;
    p.tilt_duration = duration;
    return p;
}

/* The same in the tests' tilting mode, whose walls never move: the tilt alone, composed with
 * the mode's own turn of gravity (2 degrees, then 1 more over the deformation). */
static cdem_params still_params(double angle, double duration) {
    cdem_params p = tilt_params(angle, duration);
    p.mode = CDEM_MODE_TEST_TILT;
    return p;
}

/* Degrees gravity points from -y at the end of deformation step k of p's model: the mode's
 * tilt and turn, then the process's. */
static double composed_angle(const cdem_params *p, const cdem_model *m, long k) {
    cdem_tilt_schedule t;
    cdem_tilt_schedule_of(p, m, &t);
    const double turned = (double)(k < t.k_run ? k : t.k_run) / (double)t.k_run;
    return MODE_TILT_START + MODE_TILT_TURN * turned + cdem_tilt_angle_at(&t, k);
}

static const cdem_snapshot_array *array_named(const cdem_snapshot *s, const char *name) {
    const cdem_snapshot_array *a = cdem_snapshot_get(s, name);
    if (!a)
        fail_msg("the checkpoint has no %s", name);
    return a;
}

/* Degrees gravity points from -y toward +x in a snapshot. */
static double gravity_angle(const cdem_snapshot *s) {
    return atan2(array_of(s, "it.gravity_x")[0], -array_of(s, "it.gravity_y")[0]) * 180.0 / M_PI;
}

/* cdem_run_validate's message for p ("" when valid). */
static const char *validate_message(const cdem_params *p, cdem_error *err) {
    return cdem_run_validate(p, err) == CDEM_OK ? "" : err->msg;
}

static void expect_refused(const cdem_params *p, const char *want) {
    cdem_error err;
    const char *msg = validate_message(p, &err);
    if (!strstr(msg, want))
        fail_msg("expected a refusal containing \"%s\"; got \"%s\"", want, msg);
}

/* tilt-1 */
static void test_tilt_parameters(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    assert_true(p.tilt_angle == 0.0 && p.tilt_onset == 0.0 && isnan(p.tilt_duration));
    cdem_processes ps;
    cdem_error err;
    assert_int_equal(cdem_processes_init(&ps, &p, &err), CDEM_OK);
    for (int j = 0; j < ps.n; j++)
        assert_null(ps.ops[j]->gravity); /* no process turns gravity by default */
    cdem_processes_free(&ps);
    /* the record of a run without a tilt has no [tilt]; with one, its keys */
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    cdem_params_write_record(&p, f);
    fclose(f);
    assert_null(strstr(text, "[tilt]"));
    free(text);
    cdem_params q = tilt_params(2.0, 50.0);
    f = open_memstream(&text, &len);
    cdem_params_write_record(&q, f);
    fclose(f);
    assert_non_null(strstr(text, "[tilt]"));
    assert_non_null(strstr(text, "\nangle = 2\n"));
    assert_non_null(strstr(text, "\nduration = 50\n"));
    assert_null(strstr(text, "\nonset = ")); /* left at its default */
    free(text);
    assert_string_equal(validate_message(&q, &err), "");
    /* beyond 45 degrees, either way */
    q.tilt_angle = 50.0;
    expect_refused(&q, "[tilt] angle = 50: must be between -45 and 45 degrees");
    q.tilt_angle = -46.0;
    expect_refused(&q, "[tilt] angle = -46: must be between -45 and 45 degrees");
    cdem_params o = tilt_params(0.0, 50.0);
    assert_int_equal(cdem_params_override(&o, "tilt.angle=50", &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "tilt.angle=50"));
    assert_non_null(strstr(err.msg, "must be between -45 and 45 degrees"));
    /* a window past the runtime, and past it by its onset alone */
    q = tilt_params(2.0, 80.0);
    q.tilt_onset = 30.0;
    expect_refused(&q, "[tilt] onset + duration = 30 + 80 s: the tilting would end after the "
                       "run's");
    q.tilt_onset = 150.0;
    q.tilt_duration = NAN;
    expect_refused(&q, "[tilt] onset = 150 s: the tilting would begin after the run's");
    /* levels and loads horizontal in the model's frame */
    q = tilt_params(2.0, 50.0);
    q.erosion = 1;
    expect_refused(&q, "[tilt] angle = 2 with [surface] erosion = on");
    q = tilt_params(2.0, 50.0);
    q.sedimentation = 1;
    expect_refused(&q, "[tilt] angle = 2 with [surface] sedimentation = on");
    /* a mode without gravity */
    q = tilt_params(2.0, 50.0);
    q.mode = CDEM_MODE_BIAXIAL;
    expect_refused(&q, "[tilt] angle = 2: the biaxial mode turns gravity off");
}

/* tilt-2 */
static void test_tilt_walls_carry_the_tilted_weight(void **state) {
    (void)state;
    const double angle = 5.0;
    const cdem_params p = still_params(angle, 20.0); /* 20 s of tilting, 80 s at rest */
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_run_ctx *r = open_run(&p, NULL);
    /* the last series sample (boundary forces current) */
    const long at = m.total_steps / p.series_interval * p.series_interval;
    assert_int_equal(cdem_run_advance(r, at, &err), CDEM_OK);
    cdem_snapshot *snap = capture(r);
    const double total = composed_angle(&p, &m, at - m.equil_steps);
    assert_true(fabs(total - (MODE_TILT_START + MODE_TILT_TURN + angle)) < 0.05);
    assert_true(fabs(gravity_angle(snap) - total) < 1e-9);
    const cdem_snapshot_array *na = array_named(snap, "state.flags");
    const uint32_t *flags = (const uint32_t *)na->data;
    const double *fx = array_of(snap, "state.fx"), *fy = array_of(snap, "state.fy");
    const double *mass = array_of(snap, "state.mass"), *vx = array_of(snap, "state.vx"),
                 *vy = array_of(snap, "state.vy");
    const double gx = array_of(snap, "it.gravity_x")[0], gy = array_of(snap, "it.gravity_y")[0];
    const double c = m.damping * p.deformation_damping;
    double wall_x = 0.0, wall_y = 0.0, load_x = 0.0, load_y = 0.0;
    for (size_t i = 0; i < na->count; i++) {
        if (flags[i] & CDEM_FLAGS_BOUNDARY) {
            wall_x += fx[i];
            wall_y += fy[i];
        } else { /* Newton at rest: the walls carry the weight less the drag of the creep */
            load_x += mass[i] * gx - c * vx[i];
            load_y += mass[i] * gy - c * vy[i];
        }
    }
    const double carried = atan2(wall_x, -wall_y) * 180.0 / M_PI;
    const double expected = atan2(load_x, -load_y) * 180.0 / M_PI;
    if (fabs(carried - total) > 0.05 || fabs(expected - total) > 0.05 ||
        fabs(hypot(wall_x, wall_y) / hypot(load_x, load_y) - 1.0) > 0.01)
        fail_msg("the walls carry %.6g N/m at %.4f degrees from -y; the weight less the drag is "
                 "%.6g N/m at %.4f degrees; gravity %g degrees",
                 hypot(wall_x, wall_y), carried, hypot(load_x, load_y), expected, total);
    cdem_snapshot_free(snap);
    assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
}

static int by_value(const void *a, const void *b) {
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of the free elements' displacements from a to b (matched by id) after the best
 * rigid motion (translation and rotation about the centroid), over the height h: a measure of
 * the internal strain (the median, so that a few loose grains rolling on the surface do not
 * stand for the cover). */
static double internal_strain(const cdem_snapshot *a, const cdem_snapshot *b, double h) {
    const cdem_snapshot_array *ia = array_named(a, "state.id"), *ib = array_named(b, "state.id");
    const int32_t *ida = (const int32_t *)ia->data, *idb = (const int32_t *)ib->data;
    const uint32_t *fa = (const uint32_t *)array_named(a, "state.flags")->data;
    const double *xa = array_of(a, "state.x"), *ya = array_of(a, "state.y");
    const double *xb = array_of(b, "state.x"), *yb = array_of(b, "state.y");
    int32_t max_id = 0;
    for (size_t i = 0; i < ib->count; i++)
        max_id = idb[i] > max_id ? idb[i] : max_id;
    long *where = malloc(((size_t)max_id + 1) * sizeof *where);
    assert_non_null(where);
    for (int32_t k = 0; k <= max_id; k++)
        where[k] = -1;
    for (size_t i = 0; i < ib->count; i++)
        where[idb[i]] = (long)i;
    /* pairs: p (before), q (after) */
    double px = 0, py = 0, qx = 0, qy = 0;
    long n = 0;
    for (size_t i = 0; i < ia->count; i++) {
        if ((fa[i] & CDEM_FLAGS_BOUNDARY) || ida[i] > max_id || where[ida[i]] < 0)
            continue;
        const long j = where[ida[i]];
        px += xa[i], py += ya[i], qx += xb[j], qy += yb[j];
        n++;
    }
    assert_true(n > 100);
    px /= n, py /= n, qx /= n, qy /= n;
    double sin_sum = 0.0, cos_sum = 0.0; /* the rotation: atan2(sum p x q, sum p . q) */
    for (size_t i = 0; i < ia->count; i++) {
        if ((fa[i] & CDEM_FLAGS_BOUNDARY) || ida[i] > max_id || where[ida[i]] < 0)
            continue;
        const long j = where[ida[i]];
        const double ax = xa[i] - px, ay = ya[i] - py, bx = xb[j] - qx, by = yb[j] - qy;
        sin_sum += ax * by - ay * bx;
        cos_sum += ax * bx + ay * by;
    }
    const double t = atan2(sin_sum, cos_sum), c = cos(t), s = sin(t);
    double *residual = malloc((size_t)n * sizeof *residual);
    assert_non_null(residual);
    long k = 0;
    for (size_t i = 0; i < ia->count; i++) {
        if ((fa[i] & CDEM_FLAGS_BOUNDARY) || ida[i] > max_id || where[ida[i]] < 0)
            continue;
        const long j = where[ida[i]];
        const double ax = xa[i] - px, ay = ya[i] - py;
        const double rx = xb[j] - qx - (c * ax - s * ay), ry = yb[j] - qy - (s * ax + c * ay);
        residual[k++] = hypot(rx, ry);
    }
    qsort(residual, (size_t)n, sizeof *residual, by_value);
    const double median = residual[n / 2];
    free(residual);
    free(where);
    return median / h;
}

/* The end of p's run, its gravity checked. */
static cdem_snapshot *run_to_end(const cdem_params *p) {
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(p, &m, &err), CDEM_OK);
    cdem_run_ctx *r = open_run(p, NULL);
    assert_int_equal(cdem_run_advance(r, m.total_steps, &err), CDEM_OK);
    cdem_snapshot *end = capture(r);
    assert_true(fabs(gravity_angle(end) - composed_angle(p, &m, m.total_steps - m.equil_steps)) <
                1e-9);
    assert_int_equal(cdem_run_close(r, CDEM_OK, &err), CDEM_OK);
    return end;
}

/* The internal strain the tilt of p makes: between the ends of the same run untilted and
 * tilted (the same until the tilt begins, so that the settling both share cancels). */
static double strain_of_tilt(const cdem_params *p) {
    cdem_params untilted = *p;
    untilted.tilt_angle = 0.0;
    cdem_snapshot *a = run_to_end(&untilted), *b = run_to_end(p);
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(p, &m, &err), CDEM_OK);
    const double e = internal_strain(a, b, m.height_m);
    cdem_snapshot_free(a);
    cdem_snapshot_free(b);
    return e;
}

/* tilt-3 */
static void test_tilt_rigid_cover_only_rotates(void **state) {
    (void)state;
    /* 250 m high, with the contact constants of 1000 m elements: stiff against its weight */
    cdem_params p = still_params(10.0, 20.0);
    p.unit_scaling = 100.0; /* 250 m high, with the contact constants of 1000 m elements */
    p.keep_constants = 1;
    p.damping_mode = CDEM_DAMPING_CONTACT; /* no drag on the deformation steps: free to flow */
    p.equilibration = 100;
    p.runtime = 160; /* 20 s of tilting, 40 s at rest */
    cdem_params rigid = p, free_slip = p;
    rigid.material = CDEM_MATERIAL_BONDED;
    free_slip.element.friction = free_slip.wall.friction = 0.0;
    free_slip.element.cohesion = free_slip.wall.cohesion = 0.0;
    cdem_error err;
    cdem_params check = rigid; /* the parameters are valid (in a mode of parameter files) */
    check.mode = CDEM_MODE_PLANAR_FAULT;
    assert_string_equal(validate_message(&check, &err), "");
    check = free_slip;
    check.mode = CDEM_MODE_PLANAR_FAULT;
    assert_string_equal(validate_message(&check, &err), "");
    const double e_rigid = strain_of_tilt(&rigid), e_free = strain_of_tilt(&free_slip);
    print_message("tilt-3: internal strain %.3g (bonded) vs %.3g (free slip): %.3g %%\n", e_rigid,
                  e_free, 100.0 * e_rigid / e_free);
    /* measured 0.00215 against 0.115 (1.9 %); the 1 % is met only at 25 m high (0.99 %
     * at unit_scaling 10, too slow for this suite): docs/solver.md, "Regional tilt" */
    if (!(e_free > 0.05 && e_rigid < 0.03 * e_free))
        fail_msg("the bonded cover's internal strain %.3g is not below 3 %% of the free-slip "
                 "cover's %.3g (which must flow: > 0.05)",
                 e_rigid, e_free);
}

/* tilt-4 */
static void test_tilt_resumed_bit_identical(void **state) {
    (void)state;
    const cdem_params p = still_params(3.0, 60.0);
    cdem_error err;
    cdem_run_ctx *straight = open_run(&p, NULL);
    const long total = cdem_run_total_steps(straight);
    assert_int_equal(cdem_run_advance(straight, total, &err), CDEM_OK);
    cdem_snapshot *end_straight = capture(straight);
    assert_int_equal(cdem_run_close(straight, CDEM_OK, &err), CDEM_OK);

    cdem_model m;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_tilt_schedule t;
    cdem_tilt_schedule_of(&p, &m, &t);
    const long k_mid = (t.k_begin + t.k_end) / 2 + 7; /* gravity is turning */
    cdem_run_ctx *first = open_run(&p, NULL);
    assert_int_equal(cdem_run_advance(first, m.equil_steps + k_mid, &err), CDEM_OK);
    cdem_snapshot *at_mid = capture(first);
    assert_int_equal(cdem_run_close(first, CDEM_OK, &err), CDEM_OK); /* the "kill" */
    const double mid = gravity_angle(at_mid);
    assert_true(fabs(mid - composed_angle(&p, &m, k_mid)) < 1e-9);
    assert_true(fabs(cdem_tilt_angle_at(&t, k_mid) - 1.5) < 0.01); /* half way */

    cdem_run_ctx *resumed = open_run(&p, at_mid);
    assert_int_equal(cdem_run_current_step(resumed), m.equil_steps + k_mid);
    assert_int_equal(cdem_run_advance(resumed, total, &err), CDEM_OK);
    cdem_snapshot *end_resumed = capture(resumed);
    assert_int_equal(cdem_run_close(resumed, CDEM_OK, &err), CDEM_OK);
    const char *diff = NULL;
    if (!cdem_snapshot_equal(end_straight, end_resumed, &diff))
        fail_msg("the resumed run differs from the straight one at %s", diff ? diff : "?");
    assert_true(fabs(gravity_angle(end_resumed) - (MODE_TILT_START + MODE_TILT_TURN + 3.0)) < 1e-9);
    cdem_snapshot_free(at_mid);
    cdem_snapshot_free(end_straight);
    cdem_snapshot_free(end_resumed);
}

/* tilt-5 */
static void test_tilt_summary_and_schedule(void **state) {
    (void)state;
    cdem_params p = tilt_params(-2.0, 40.0);
    p.tilt_onset = 20.0;
    cdem_model m;
    cdem_error err;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    cdem_tilt_schedule t;
    cdem_tilt_schedule_of(&p, &m, &t);
    assert_int_equal(t.k_begin, lround(20.0 / m.dt));
    assert_int_equal(t.k_end - t.k_begin, lround(40.0 / m.dt));
    assert_true(cdem_tilt_angle_at(&t, 0) == 0.0 && cdem_tilt_angle_at(&t, t.k_begin) == 0.0);
    assert_true(fabs(cdem_tilt_angle_at(&t, (t.k_begin + t.k_end) / 2) + 1.0) < 1e-3);
    assert_true(cdem_tilt_angle_at(&t, t.k_end) == -2.0 && cdem_tilt_angle_at(&t, t.k_run) == -2.0);
    char *text = NULL;
    assert_int_equal(cdem_summary_text(&p, &m, 100, 10, 1, &text, &err), CDEM_OK);
    const char *want[] = {
        "\nRegional tilt\n",
        "the whole model (box and base) rotates rigidly relative to gravity",
        "2 degrees: the margin comes to dip toward -x",
        "untilted to 20.0109 s after equilibration, tilting at -0.05001 degrees/s to 60.0046 s "
        "(deformation steps 710 to 2129), then held to the end (99.9982 s)",
        "-2 degrees from -y",
    };
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++)
        if (!strstr(text, want[k]))
            fail_msg("the summary lacks \"%s\":\n%s", want[k],
                     strstr(text, "Regional tilt") ? strstr(text, "Regional tilt") : text);
    free(text);
    /* without a tilt, no section */
    p.tilt_angle = 0.0;
    assert_int_equal(cdem_summary_text(&p, &m, 100, 10, 1, &text, &err), CDEM_OK);
    assert_null(strstr(text, "Regional tilt"));
    free(text);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tilt_parameters),
        cmocka_unit_test(test_tilt_walls_carry_the_tilted_weight),
        cmocka_unit_test(test_tilt_rigid_cover_only_rotates),
        cmocka_unit_test(test_tilt_resumed_bit_identical),
        cmocka_unit_test(test_tilt_summary_and_schedule),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
