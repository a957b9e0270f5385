/* Tests of mohr.[ch] (Mohr-Coulomb envelope fit) and the mohr subcommand with --data. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cairo.h>
#include <cmocka.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "assert_near.h"
#include "cmd_plot.h"
#include "h5format.h"
#include "mohr.h"
#include "params.h"
#include "scratch.h"

#include <fcntl.h>
#include <unistd.h>

static const double deg = 3.14159265358979323846 / 180.0;

/* Peak differential stress of a test at confining pressure s3 on the envelope (C, phi). */
static double peak_q(double s3, double C, double phi) {
    double t = tan(M_PI / 4 + phi / 2);
    return 2 * C * t + s3 * t * t - s3;
}

static void test_mohr_exact_circles_recover_c_and_phi(void **state) {
    (void)state;
    const double C = 4e6, phi = 34 * deg;
    double s3[4] = {0.0, 5e6, 10e6, 20e6}, q[4];
    for (int i = 0; i < 4; i++)
        q[i] = peak_q(s3[i], C, phi);
    cdem_mohr_fit f;
    cdem_error err;
    assert_int_equal(cdem_mohr_fit_envelope(s3, q, 4, &f, &err), CDEM_OK);
    assert_near(f.cohesion / C, 1.0, 1e-9);
    assert_near(f.friction / phi, 1.0, 1e-9);
    /* every circle is tangent to the envelope: distance from the centre to the line = radius */
    for (int i = 0; i < 4; i++) {
        double c = s3[i] + q[i] / 2, r = q[i] / 2;
        double dist = (f.cohesion + c * tan(f.friction)) * cos(f.friction);
        assert_near(dist / r, 1.0, 1e-9);
    }
    /* two tests: exact, no uncertainty */
    assert_int_equal(cdem_mohr_fit_envelope(s3 + 1, q + 1, 2, &f, &err), CDEM_OK);
    assert_near(f.cohesion / C, 1.0, 1e-9);
    assert_near(f.friction / phi, 1.0, 1e-9);
    assert_true(isnan(f.cohesion_err) && isnan(f.friction_err));
}

static void test_mohr_noisy_uncertainties_cover_truth(void **state) {
    (void)state;
    const double C = 4e6, phi = 34 * deg;
    enum { N = 8 };
    double s3[N], q[N];
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 12345);
    int covered_c = 0, covered_phi = 0;
    const int trials = 40;
    for (int t = 0; t < trials; t++) {
        for (int i = 0; i < N; i++) {
            s3[i] = 2.5e6 * i;
            q[i] = peak_q(s3[i], C, phi) + gsl_ran_gaussian(rng, 1e6);
        }
        cdem_mohr_fit f;
        cdem_error err;
        assert_int_equal(cdem_mohr_fit_envelope(s3, q, N, &f, &err), CDEM_OK);
        assert_true(f.cohesion_err > 0 && f.friction_err > 0);
        covered_c += fabs(f.cohesion - C) <= 2 * f.cohesion_err;
        covered_phi += fabs(f.friction - phi) <= 2 * f.friction_err;
        if (t == 0) { /* the first sample: within 3 sigma and errors of a sensible size */
            assert_true(fabs(f.cohesion - C) <= 3 * f.cohesion_err);
            assert_true(fabs(f.friction - phi) <= 3 * f.friction_err);
            assert_true(f.friction_err < 5 * deg && f.cohesion_err < 2e6);
        }
    }
    gsl_rng_free(rng);
    /* 2 sigma covers ~95 %: at least 80 % of 40 trials */
    assert_true(covered_c >= 32);
    assert_true(covered_phi >= 32);
}

static void test_mohr_bad_input_messages(void **state) {
    (void)state;
    cdem_mohr_fit f;
    cdem_error err;
    double s3[3] = {1e6, 1e6, 1e6}, q[3] = {5e6, 5e6, 5e6};
    assert_int_equal(cdem_mohr_fit_envelope(s3, q, 1, &f, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "at least 2"));
    assert_int_equal(cdem_mohr_fit_envelope(s3, q, 3, &f, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "same confining pressure"));
    double s3b[2] = {0, 1e6}, qb[2] = {5e6, -1};
    assert_int_equal(cdem_mohr_fit_envelope(s3b, qb, 2, &f, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "test 2"));
    double qc[2] = {5e6, 4e6}; /* sigma1 falls with sigma3: b < 1 */
    assert_int_equal(cdem_mohr_fit_envelope(s3b, qc, 2, &f, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "negative friction angle"));
}

static void test_mohr_table_and_command(void **state) {
    (void)state;
    char path[512], png[512], bad[512];
    snprintf(path, sizeof path, "%s/mohr_tests.txt", scratch_root());
    snprintf(png, sizeof png, "%s/mohr.png", scratch_root());
    snprintf(bad, sizeof bad, "%s/mohr_bad.txt", scratch_root());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "# sigma3 q (N/m)\n");
    const double C = 4e6, phi = 34 * deg;
    for (int i = 0; i < 3; i++)
        fprintf(f, "%.17g %.17g\n\n", 4e6 * i, peak_q(4e6 * i, C, phi));
    fclose(f);
    double *s3, *q;
    size_t n;
    cdem_error err;
    assert_int_equal(cdem_mohr_read_table(path, &s3, &q, &n, &err), CDEM_OK);
    assert_int_equal(n, 3);
    assert_near(s3[2], 8e6, 0);
    cdem_mohr_fit fit;
    assert_int_equal(cdem_mohr_fit_envelope(s3, q, n, &fit, &err), CDEM_OK);
    assert_near(fit.friction / phi, 1.0, 1e-9);
    free(s3);
    free(q);
    char *argv[] = {"mohr", "--data", path, "-o", png};
    assert_int_equal(cdem_cmd_plot_mohr(5, argv), 0);
    cairo_surface_t *img = cairo_image_surface_create_from_png(png);
    assert_int_equal(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
    assert_int_equal(cairo_image_surface_get_width(img), 700);
    cairo_surface_destroy(img);
    f = fopen(bad, "w");
    assert_non_null(f);
    fprintf(f, "1e6 2e6\n3e6 oops\n");
    fclose(f);
    assert_int_equal(cdem_mohr_read_table(bad, &s3, &q, &n, &err), CDEM_ERR_PARSE);
    assert_non_null(strstr(err.msg, "line 2"));
    assert_null(s3);
    char *argv2[] = {"mohr", "--data", bad};
    assert_int_equal(cdem_cmd_plot_mohr(3, argv2), 1);
    char *argv3[] = {"mohr", "only_one.h5"};
    assert_int_equal(cdem_cmd_plot_mohr(2, argv3), 2);
}

/* fontconfig, which cairo's text uses, keeps a process-lifetime configuration that only
 * FcFini releases (as in test_render.c). LeakSanitizer reads this hook in the asan build. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) {
    return "leak:libfontconfig.so\n";
}

/* A synthetic biaxial run: stress rises linearly to the peak q at 2 % strain, then
 * softens to 0.7 q. */
static void write_biaxial_run(const char *path, double sigma3, double q, cdem_mode mode) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = mode;
    p.confining_pressure = sigma3;
    cdem_run_meta meta = {&p, "", "biaxial test", "0", "test", 0};
    cdem_h5_writer *w;
    cdem_error err;
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    for (int k = 0; k <= 40; k++) {
        double e = 0.001 * k;
        double sd = e <= 0.02 ? q * e / 0.02 : q * (1.0 - 0.3 * (e - 0.02) / 0.02);
        cdem_series_sample smp = {
            .step = k, .time = k, .axial_strain = e, .differential_stress = sd, .sea_level = NAN};
        assert_int_equal(cdem_h5_writer_append_series(w, &smp, &err), CDEM_OK);
    }
    cdem_state s = {0};
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 0.0, 0.0, 50.0, 1.0, 1, 0, 0, NULL, &err), CDEM_OK);
    cdem_increment_info info = {.number = 0, .sea_level = NAN, .n_elements = 1};
    assert_int_equal(cdem_h5_writer_write_increment(w, &info, &s, &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
    cdem_state_free(&s);
}

static void test_mohr_command_on_runs(void **state) {
    (void)state;
    const double C = 4e6, phi = 34 * deg;
    char runs[3][512], png[512], out[512];
    for (int i = 0; i < 3; i++) {
        snprintf(runs[i], sizeof runs[i], "%s/mohr_run%d.h5", scratch_root(), i);
        write_biaxial_run(runs[i], 5e6 * i, peak_q(5e6 * i, C, phi), CDEM_MODE_BIAXIAL);
    }
    snprintf(png, sizeof png, "%s/mohr_runs.png", scratch_root());
    snprintf(out, sizeof out, "%s/mohr_stdout.txt", scratch_root());
    char *argv[] = {"mohr", runs[0], runs[1], runs[2], "-o", png};
    fflush(stdout);
    int saved = dup(1), fd = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(saved >= 0 && fd >= 0);
    dup2(fd, 1);
    int rc = cdem_cmd_plot_mohr(6, argv);
    fflush(stdout);
    dup2(saved, 1);
    close(fd);
    close(saved);
    assert_int_equal(rc, 0);
    char text[2048] = "";
    FILE *f = fopen(out, "r");
    assert_non_null(f);
    size_t got = fread(text, 1, sizeof text - 1, f);
    text[got] = 0;
    fclose(f);
    assert_non_null(strstr(text, "cohesion = 4 +- "));
    assert_non_null(strstr(text, "friction angle = 34.00 +- "));
    assert_non_null(strstr(text, "sigma3 = 10 MPa"));
    cairo_surface_t *img = cairo_image_surface_create_from_png(png);
    assert_int_equal(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
    assert_int_equal(cairo_image_surface_get_width(img), 1400);
    cairo_surface_destroy(img);
    /* a run of another mode is refused by name */
    write_biaxial_run(runs[2], 1e7, 2e7, CDEM_MODE_PLANAR_FAULT);
    char *argv2[] = {"mohr", runs[0], runs[2]};
    assert_int_equal(cdem_cmd_plot_mohr(3, argv2), 1);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mohr_exact_circles_recover_c_and_phi),
        cmocka_unit_test(test_mohr_noisy_uncertainties_cover_truth),
        cmocka_unit_test(test_mohr_bad_input_messages),
        cmocka_unit_test(test_mohr_table_and_command),
        cmocka_unit_test(test_mohr_command_on_runs),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    cairo_debug_reset_static_data(); /* drop cairo's font caches before LeakSanitizer looks */
    return failed;
}
