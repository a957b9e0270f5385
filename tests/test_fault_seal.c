/* Tests of fault_seal.[ch] (throw, heave and juxtaposition across a fault zone) on synthetic
 * states: horizontal layers of square-packed rows of known thickness whose hanging wall is
 * moved down a straight (vertical or dipping) zone by a known throw, so the horizons, the
 * juxtaposition table and the seal layers' loss throw are known exactly; bad input; and one
 * end to end run of `cdem-strain fault-seal` on a small planar-fault run made by cdem-run. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "analysis.h"
#include "fault_seal.h"
#include "run_file.h"
#include "scratch.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#define R        10.0 /* m, every element's radius */
#define WIDTH    2000.0
#define X0       1000.0 /* the zone's x at y = 0 */
#define N_LAYERS 6

/* Rows of each layer, bottom up: thickness 2 R x rows. */
static const int rows_of[N_LAYERS] = {3, 5, 4, 6, 3, 5};

/* Height of the top of layer L (1..N_LAYERS) before faulting; 0 for L = 0 (the base). */
static double top_before(int L) {
    double y = 0.0;
    for (int k = 0; k < L; k++)
        y += 2.0 * R * rows_of[k];
    return y;
}

/* The zone line x = X0 + c (0 - y) dipping toward +x with c = 1 / tan(dip) (0: vertical). */
static double zone_x(double c, double y) {
    return X0 - c * y;
}

/* Layers of square-packed rows; the elements right of the line (the hanging wall) moved down
 * the line by `throw_m` (and right by c x throw_m, so they stay on their side). */
static void make_faulted(cdem_state *s, double c, double throw_m) {
    cdem_error err;
    assert_int_equal(cdem_state_init(s, 20000, 0, &err), CDEM_OK);
    int row = 0;
    for (int L = 1; L <= N_LAYERS; L++)
        for (int k = 0; k < rows_of[L - 1]; k++, row++) {
            const double y = R + 2.0 * R * row;
            for (double x = R; x < WIDTH; x += 2.0 * R) {
                const int hanging = x > zone_x(c, y);
                assert_int_equal(cdem_state_append(s, -1, hanging ? x + c * throw_m : x,
                                                   hanging ? y - throw_m : y, R, 1.0, L, 0, 0, NULL,
                                                   &err),
                                 CDEM_OK);
            }
        }
}

static cdem_seal_zone zone_of(double c) {
    return (cdem_seal_zone){zone_x(c, 500.0), 500.0, zone_x(c, -500.0), -500.0, 2.0 * R, 8.0 * R};
}

/* The layer holding height y in (base, top] with the tops lowered by `down`; 0 for none. */
static int expected_layer(double y, double down) {
    for (int L = 1; L <= N_LAYERS; L++)
        if (y > top_before(L - 1) - down && y <= top_before(L) - down)
            return L;
    return 0;
}

/* 1 when y is within 1e-6 m of a boundary of either side (where rounding may pick either). */
static int on_boundary(double y, double down) {
    for (int L = 0; L <= N_LAYERS; L++)
        if (fabs(y - top_before(L)) < 1e-6 || fabs(y - (top_before(L) - down)) < 1e-6)
            return 1;
    return 0;
}

static void check_offset(double c, double throw_m) {
    cdem_state s;
    make_faulted(&s, c, throw_m);
    const cdem_seal_zone z = zone_of(c);
    const int seal = 3;
    cdem_fault_seal_result r;
    cdem_error err;
    assert_int_equal(cdem_fault_seal_measure(&s, &z, &seal, 1, 0.0, &r, &err), CDEM_OK);
    assert_int_equal(r.hanging_wall_right, 1);
    assert_true(fabs(r.mean_radius - R) < 1e-9);
    /* a throw at every horizon within one radius, and the total */
    assert_int_equal(r.n_horizons, N_LAYERS);
    for (size_t k = 0; k < r.n_horizons; k++) {
        assert_int_equal(r.horizon[k].layer, (int)k + 1);
        assert_true(fabs(r.horizon[k].throw_m - throw_m) < R);
        assert_true(fabs(r.horizon[k].footwall_top - top_before((int)k + 1)) < R);
        assert_true(fabs(r.horizon[k].heave - c * throw_m) < R);
    }
    assert_true(fabs(r.total_throw - throw_m) < R);
    /* the juxtaposition table is that of the offset layers, bottom to top */
    assert_true(r.n_rows > 10);
    assert_true(fabs(r.row[0].height - (-throw_m + 0.25 * R)) < 1e-9);
    assert_true(r.row[r.n_rows - 1].height <= top_before(N_LAYERS));
    assert_true(r.row[r.n_rows - 1].height > top_before(N_LAYERS) - 0.5 * R);
    size_t checked = 0;
    for (size_t k = 0; k < r.n_rows; k++) {
        const double y = r.row[k].height;
        if (on_boundary(y, throw_m))
            continue;
        assert_int_equal(r.row[k].footwall, expected_layer(y, 0.0));
        assert_int_equal(r.row[k].hanging, expected_layer(y, throw_m));
        checked++;
    }
    assert_true(checked + 8 > r.n_rows);
    /* the seal layer: self-juxtaposed while the throw is below its thickness, lost at a throw
     * equal to its thickness */
    const double thickness = 2.0 * R * rows_of[seal - 1];
    assert_int_equal(r.n_seals, 1);
    assert_int_equal(r.seal[0].layer, seal);
    assert_int_equal(r.seal[0].self_juxtaposed, throw_m < thickness);
    assert_true(fabs(r.seal[0].loss_throw - thickness) < R);
    assert_true(fabs(r.seal[0].overlap - (thickness - throw_m)) < R);
    cdem_fault_seal_free(&r);
    cdem_state_free(&s);
}

static void test_fault_seal_vertical_zone(void **st) {
    (void)st;
    const double throws[] = {30.0, 50.0, 70.0, 90.0, 130.0, 250.0};
    for (size_t k = 0; k < sizeof throws / sizeof throws[0]; k++)
        check_offset(0.0, throws[k]);
}

static void test_fault_seal_dipping_zone(void **st) {
    (void)st;
    const double c = 1.0 / tan(60.0 * M_PI / 180.0);
    const double throws[] = {40.0, 75.0, 85.0, 160.0};
    for (size_t k = 0; k < sizeof throws / sizeof throws[0]; k++)
        check_offset(c, throws[k]);
}

/* The left side down: the hanging wall is found on the left, the throw is positive. */
static void test_fault_seal_hanging_wall_left(void **st) {
    (void)st;
    cdem_state s;
    make_faulted(&s, 0.0, -60.0);
    const cdem_seal_zone z = zone_of(0.0);
    cdem_fault_seal_result r;
    cdem_error err;
    assert_int_equal(cdem_fault_seal_measure(&s, &z, NULL, 0, 0.0, &r, &err), CDEM_OK);
    assert_int_equal(r.hanging_wall_right, 0);
    assert_true(fabs(r.total_throw - 60.0) < R);
    cdem_fault_seal_free(&r);
    cdem_state_free(&s);
}

static void test_fault_seal_bad_input(void **st) {
    (void)st;
    cdem_state s;
    make_faulted(&s, 0.0, 50.0);
    cdem_seal_zone z = zone_of(0.0);
    cdem_fault_seal_result r;
    cdem_error err;
    const int missing = 30;
    assert_int_equal(cdem_fault_seal_measure(&s, &z, &missing, 1, 0.0, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "seal layer 30 does not exist: the layers are 1..6"));
    /* a zone outside the layers */
    z.x_top = z.x_bottom = 5000.0;
    assert_int_equal(cdem_fault_seal_measure(&s, &z, NULL, 0, 0.0, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "no layer is found on both sides"));
    z = zone_of(0.0);
    z.y_bottom = z.y_top;
    assert_int_equal(cdem_fault_seal_measure(&s, &z, NULL, 0, 0.0, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "two points at different heights"));
    /* a run without layers */
    for (size_t i = 0; i < s.n; i++)
        s.layer[i] = 0;
    z = zone_of(0.0);
    assert_int_equal(cdem_fault_seal_measure(&s, &z, NULL, 0, 0.0, &r, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "the run has no layers"));
    cdem_state_free(&s);
}

/* Runs cmd (2>&1); output (truncated) in out; returns the exit status. */
static int run(const char *cmd, char *out, size_t n) {
    char full[8192];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    assert_non_null(p);
    size_t got = fread(out, 1, n - 1, p);
    out[got] = '\0';
    while (fread(full, 1, sizeof full, p) > 0) {
    }
    const int status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* `cdem-strain fault-seal` on a small planar-fault run (2.5 km high, 420 m of boundary
 * displacement, half a second): the CSV headers, a positive throw below the boundary's
 * displacement, and the errors of a missing seal layer and an increment outside the run. */
static void test_fault_seal_cli_on_a_planar_run(void **st) {
    (void)st;
    scratch_dir dir;
    assert_int_equal(scratch_dir_make(&dir, "fault_seal"), 0);
    const char *b = getenv("CDEM_BUILD");
    char cmd[6000], out[65536], file[1100];
    snprintf(file, sizeof file, "%s/planar.h5", dir.dir);
    snprintf(cmd, sizeof cmd,
             "OMP_NUM_THREADS=1 '%s/cdem-run' -s boundary.mode=planar-fault -s "
             "assembly.height=2.5 -s time.equilibration=100 -s time.runtime=700 -s "
             "time.display_interval=50 -o '%s' > /dev/null",
             b ? b : "build", file);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    /* the boundary's displacement at the last increment */
    cdem_analysis *a;
    cdem_error err;
    assert_int_equal(cdem_analysis_open(file, &a, &err), CDEM_OK);
    const double net = cdem_analysis_info(a, cdem_analysis_count(a) - 1)->net_displacement;
    cdem_analysis_close(a);
    assert_true(net > 100.0);

    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' fault-seal '%s' -o '%s/j.csv'", b ? b : "build",
             file, dir.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    double throw_m = NAN;
    const char *at = strstr(out, "total throw ");
    assert_non_null(at);
    assert_int_equal(sscanf(at, "total throw %lf", &throw_m), 1);
    assert_true(throw_m > 0.0);
    assert_true(throw_m < net);
    snprintf(cmd, sizeof cmd, "head -1 '%s/j.csv'", dir.dir);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_string_equal(out, "height,footwall_layer,hanging_wall_layer\n");

    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' fault-seal '%s' --table seals --seal-layers 12",
             b ? b : "build", file);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "layer,footwall_base,footwall_top,hanging_wall_base,"
                                "hanging_wall_top,throw,overlap,self_juxtaposed,loss_throw\n12,"));
    assert_non_null(strstr(out, "seal layer 12: throw "));

    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' fault-seal '%s' --table throw", b ? b : "build",
             file);
    assert_int_equal(run(cmd, out, sizeof out), 0);
    assert_non_null(strstr(out, "layer,height,footwall_top,hanging_wall_top,throw,heave\n1,"));

    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' fault-seal '%s' --seal-layers 3,99",
             b ? b : "build", file);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "seal layer 99 does not exist: the layers are 1.."));

    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' fault-seal '%s' --increment 99", b ? b : "build",
             file);
    assert_int_equal(run(cmd, out, sizeof out), 1);
    assert_non_null(strstr(out, "increment 99 does not exist"));

    snprintf(cmd, sizeof cmd, "'%s/cdem-strain' fault-seal '%s' --seal-layers 3,x", b ? b : "build",
             file);
    assert_int_equal(run(cmd, out, sizeof out), 2);
    assert_non_null(strstr(out, "--seal-layers must be"));
    assert_int_equal(scratch_dir_remove(&dir), 0);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fault_seal_vertical_zone),
        cmocka_unit_test(test_fault_seal_dipping_zone),
        cmocka_unit_test(test_fault_seal_hanging_wall_left),
        cmocka_unit_test(test_fault_seal_bad_input),
        cmocka_unit_test(test_fault_seal_cli_on_a_planar_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
