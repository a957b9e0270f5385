/* Tests of plot.[ch] (line plots) and the plot-series subcommand (cmd_plot.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cairo.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "assert_near.h"
#include "cmd_plot.h"
#include "h5format.h"
#include "params.h"
#include "plot.h"
#include "scratch.h"

static long file_size(const char *path) {
    struct stat sb;
    return stat(path, &sb) == 0 ? (long)sb.st_size : -1;
}

/* ARGB32 pixel at device (x, y) of a PNG surface. */
static uint32_t pixel(cairo_surface_t *s, double x, double y) {
    int ix = (int)floor(x), iy = (int)floor(y);
    const unsigned char *d = cairo_image_surface_get_data(s);
    return (
        (const uint32_t *)(const void *)(d + (size_t)iy * cairo_image_surface_get_stride(s)))[ix];
}

static void test_plot_nice_ticks(void **state) {
    (void)state;
    double first, step;
    cdem_plot_nice_ticks(0.0, 10.0, 5, &first, &step);
    assert_near(step, 2.0, 1e-12);
    assert_near(first, 0.0, 1e-12);
    cdem_plot_nice_ticks(0.013, 0.97, 6, &first, &step);
    assert_near(step, 0.2, 1e-12);
    assert_near(first, 0.2, 1e-12);
    cdem_plot_nice_ticks(-3.3e6, 4.1e6, 6, &first, &step);
    assert_near(step, 1e6, 1e-3);
    assert_near(first, -3e6, 1e-3);
}

static void test_plot_layout_range_and_aspect(void **state) {
    (void)state;
    double x[3] = {0.3, 1.0, 9.2}, y[3] = {-0.4, 2.0, 3.7};
    cdem_plot_series s = {.x = x, .y = y, .n = 3, .line = 1};
    cdem_plot p = {.series = &s, .n_series = 1};
    cdem_plot_layout lay;
    cdem_error err;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 800, 500, &lay, &err), CDEM_OK);
    assert_true(lay.xmin <= 0.3 && lay.xmax >= 9.2 && lay.ymin <= -0.4 && lay.ymax >= 3.7);
    assert_near(lay.xmin, 0.0, 1e-12);
    assert_near(lay.xmax, 10.0, 1e-12);
    double dx, dy;
    cdem_plot_to_device(&lay, lay.xmin, lay.ymax, &dx, &dy);
    assert_near(dx, lay.plot_x, 1e-9);
    assert_near(dy, lay.plot_y, 1e-9);
    cdem_plot_to_device(&lay, lay.xmax, lay.ymin, &dx, &dy);
    assert_near(dx, lay.plot_x + lay.plot_w, 1e-9);
    assert_near(dy, lay.plot_y + lay.plot_h, 1e-9);
    p.equal_aspect = 1;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 800, 500, &lay, &err), CDEM_OK);
    assert_near(lay.plot_w / (lay.xmax - lay.xmin), lay.plot_h / (lay.ymax - lay.ymin), 1e-9);
    assert_true(lay.xmin <= 0.3 && lay.xmax >= 9.2 && lay.ymin <= -0.4 && lay.ymax >= 3.7);
}

/* Issue 46: ten curves of `calibrate` (seeds x pressures) on an eight-colour cycle drew two
 * pairs alike. Thirty series without colours of their own all differ in colour or dash; a
 * series with its own colour keeps it, solid unless dashed. */
static void test_plot_thirty_series_differ(void **state) {
    (void)state;
    cdem_plot_series s;
    memset(&s, 0, sizeof s);
    cdem_rgba c[30];
    cdem_plot_dash d[30];
    for (size_t i = 0; i < 30; i++)
        cdem_plot_series_style(&s, i, &c[i], &d[i]);
    for (size_t i = 0; i < 30; i++)
        for (size_t j = 0; j < i; j++) {
            const int same_colour = c[i].r == c[j].r && c[i].g == c[j].g && c[i].b == c[j].b;
            if (same_colour && d[i] == d[j])
                fail_msg("series %zu and %zu are drawn alike", j, i);
        }
    for (size_t i = 0; i < 10; i++) /* the first ten: ten colours, all solid */
        assert_int_equal(d[i], CDEM_PLOT_SOLID);
    s.colour = (cdem_rgba){0, 0, 0, 1};
    cdem_plot_series_style(&s, 12, &c[0], &d[0]);
    assert_true(c[0].r == 0 && c[0].a == 1 && d[0] == CDEM_PLOT_SOLID);
    s.dashed = 1;
    cdem_plot_series_style(&s, 0, &c[0], &d[0]);
    assert_int_equal(d[0], CDEM_PLOT_DASHED);
}

/* Issue 46: the legend sat in the top-right corner over the high-pressure curves' peaks. It
 * goes to the first corner that covers none of the points drawn; with every corner free it
 * stays top right. */
static void test_plot_legend_avoids_the_data(void **state) {
    (void)state;
    enum { N = 200, C = 5 };
    double x[N], y[C][N];
    cdem_plot_series s[C];
    memset(s, 0, sizeof s);
    for (int c = 0; c < C; c++) { /* stress-strain curves: rise, peak, stay high to the end */
        for (int k = 0; k < N; k++) {
            x[k] = 0.2 * k / (N - 1);
            y[c][k] = (15.0 * c + 15.0) * (1.0 - exp(-x[k] / 0.03));
        }
        s[c] = (cdem_plot_series){.x = x, .y = y[c], .n = N, .line = 1, .label = "biaxial-x.h5"};
    }
    cdem_plot p = {.series = s, .n_series = C};
    cdem_plot_layout lay;
    cdem_error err;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 700, 560, &lay, &err), CDEM_OK);
    double box[4];
    assert_int_equal(cdem_plot_legend_box(&p, &lay, box), 1);
    printf("    legend at %.0f, %.0f (%.0f x %.0f): %zu points under it\n", box[0], box[1], box[2],
           box[3], cdem_plot_points_in_box(&p, &lay, box));
    assert_true(box[2] > 0 && box[3] > 0);
    assert_int_equal(cdem_plot_points_in_box(&p, &lay, box), 0);
    /* where it was, top right, it covered the top curve */
    double old[4] = {lay.plot_x + lay.plot_w - box[2] - 0.5 * lay.font_size,
                     lay.plot_y + 0.5 * lay.font_size, box[2], box[3]};
    assert_true(cdem_plot_points_in_box(&p, &lay, old) > 0);
    /* inside the plot area */
    assert_true(box[0] >= lay.plot_x && box[0] + box[2] <= lay.plot_x + lay.plot_w);
    assert_true(box[1] >= lay.plot_y && box[1] + box[3] <= lay.plot_y + lay.plot_h);
    /* one short curve in the lower left: the legend stays top right */
    double sx[2] = {0, 1}, sy[2] = {0, 0.1};
    cdem_plot_series one = {.x = sx, .y = sy, .n = 2, .line = 1, .label = "a"};
    cdem_plot q = {.series = &one, .n_series = 1, .fix_y = 1, .ymin = 0, .ymax = 1};
    assert_int_equal(cdem_plot_layout_compute(&q, 0, 0, 700, 560, &lay, &err), CDEM_OK);
    assert_int_equal(cdem_plot_legend_box(&q, &lay, box), 1);
    assert_true(box[0] > lay.plot_x + 0.5 * lay.plot_w && box[1] < lay.plot_y + 0.5 * lay.plot_h);
    q.no_legend = 1;
    assert_int_equal(cdem_plot_legend_box(&q, &lay, box), 0);
}

static void test_plot_errors_name_the_problem(void **state) {
    (void)state;
    cdem_plot p = {0};
    cdem_plot_layout lay;
    cdem_error err;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 30, 30, &lay, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "too small"));
    p.fix_x = 1;
    p.xmin = 2;
    p.xmax = 1;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 800, 500, &lay, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "fixed x range 2 .. 1"));
    p.fix_x = 0;
    cdem_plot_series s = {.n = 4, .label = "broken"};
    p.series = &s;
    p.n_series = 1;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 800, 500, &lay, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "'broken'"));
    char path[512];
    snprintf(path, sizeof path, "%s/plot_bad.jpg", scratch_root());
    p.n_series = 0;
    assert_int_not_equal(cdem_plot_to_file(path, &p, 1, 400, 300, &err), CDEM_OK);
    assert_non_null(strstr(err.msg, ".jpg"));
    cdem_series_sample smp = {0};
    double v;
    const char *label;
    assert_int_equal(cdem_cmd_plot_column(&smp, 1, "energy", &v, &label, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "'energy'"));
    assert_non_null(strstr(err.msg, "kinetic_energy"));
}

static void test_plot_column_extraction(void **state) {
    (void)state;
    cdem_series_sample smp[2] = {{.step = 7, .contacts = 12, .differential_stress = 3.5e6},
                                 {.step = 9, .contacts = 15, .differential_stress = 4.5e6}};
    double v[2];
    const char *label;
    cdem_error err;
    assert_int_equal(cdem_cmd_plot_column(smp, 2, "contacts", v, &label, &err), CDEM_OK);
    assert_near(v[1], 15.0, 0);
    assert_int_equal(cdem_cmd_plot_column(smp, 2, "differential_stress", v, &label, &err), CDEM_OK);
    assert_near(v[0], 3.5e6, 0);
    assert_non_null(strstr(label, "N/m"));
    assert_int_equal(cdem_cmd_plot_column(smp, 2, "step", v, NULL, &err), CDEM_OK);
    assert_near(v[1], 9.0, 0);
}

#define NS 10

static void write_series_file(const char *path) {
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "", "plot test", "0", "test", 0};
    cdem_h5_writer *w;
    cdem_error err;
    assert_int_equal(cdem_h5_writer_create(path, &meta, &w, &err), CDEM_OK);
    cdem_state s = {0};
    assert_int_equal(cdem_state_init(&s, 4, 0, &err), CDEM_OK);
    assert_int_equal(cdem_state_append(&s, -1, 0.0, 0.0, 50.0, 1.0, 1, 0, 0, NULL, &err), CDEM_OK);
    for (int k = 0; k < NS; k++) {
        cdem_series_sample smp = {.step = k * 100,
                                  .time = 10.0 * k,
                                  .kinetic_energy = (double)k * k,
                                  .n_elements = 1,
                                  .axial_strain = 0.002 * k,
                                  .sea_level = NAN};
        assert_int_equal(cdem_h5_writer_append_series(w, &smp, &err), CDEM_OK);
    }
    cdem_increment_info info = {
        .number = 0, .step = 900, .time = 90.0, .sea_level = NAN, .n_elements = 1};
    assert_int_equal(cdem_h5_writer_write_increment(w, &info, &s, &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
    cdem_state_free(&s);
}

static void test_plot_series_command_draws_the_line(void **state) {
    (void)state;
    char h5[512], png[512];
    snprintf(h5, sizeof h5, "%s/plot_series.h5", scratch_root());
    snprintf(png, sizeof png, "%s/plot_series.png", scratch_root());
    write_series_file(h5);
    char *argv[] = {"plot-series", h5,        "--y", "kinetic_energy", "--x", "time", "-o",
                    png,           "--width", "800", "--height",       "500"};
    assert_int_equal(cdem_cmd_plot_series(12, argv), 0);
    cairo_surface_t *img = cairo_image_surface_create_from_png(png);
    assert_int_equal(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
    assert_int_equal(cairo_image_surface_get_width(img), 800);
    assert_int_equal(cairo_image_surface_get_height(img), 500);
    /* the same data give the same layout (margins depend on the size only) */
    double x[NS], y[NS];
    for (int k = 0; k < NS; k++) {
        x[k] = 10.0 * k;
        y[k] = (double)k * k;
    }
    cdem_plot_series s = {.x = x, .y = y, .n = NS, .line = 1};
    cdem_plot p = {.series = &s, .n_series = 1};
    cdem_plot_layout lay;
    cdem_error err;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 800, 500, &lay, &err), CDEM_OK);
    double dx, dy;
    cdem_plot_to_device(&lay, 60.0, 36.0, &dx, &dy); /* sample k = 6 */
    uint32_t on = pixel(img, dx, dy);
    unsigned r = (on >> 16) & 255, b = on & 255;
    assert_true(b > r + 60); /* the first palette colour is blue */
    /* half a tick off the grid, far from the line: background */
    cdem_plot_to_device(&lay, lay.xtick0 + 0.5 * lay.xstep, lay.ymax - 0.5 * lay.ystep, &dx, &dy);
    assert_int_equal(pixel(img, dx, dy) & 0xffffff, 0xffffff);
    cairo_surface_destroy(img);
    /* a fixed y range: the same point lands where the fixed-range layout says */
    char *argv5[] = {"plot-series", h5,        "--y", "kinetic_energy", "-o", png, "--yrange",
                     "0,40",        "--width", "800", "--height",       "500"};
    assert_int_equal(cdem_cmd_plot_series(12, argv5), 0);
    img = cairo_image_surface_create_from_png(png);
    assert_int_equal(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
    p.fix_y = 1;
    p.ymin = 0;
    p.ymax = 40;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 800, 500, &lay, &err), CDEM_OK);
    cdem_plot_to_device(&lay, 60.0, 36.0, &dx, &dy);
    on = pixel(img, dx, dy);
    assert_true((on & 255) > ((on >> 16) & 255) + 60);
    cairo_surface_destroy(img);
    char *argv6[] = {"plot-series", h5, "--y", "contacts", "-o", png, "--yrange", "5,1"};
    assert_int_equal(cdem_cmd_plot_series(8, argv6), 2);
    /* several runs, vector output, unknown column */
    char pdf[512];
    snprintf(pdf, sizeof pdf, "%s/plot_series.pdf", scratch_root());
    char *argv2[] = {"plot-series", h5, h5, "--y=contacts", "--x=step", "-o", pdf};
    assert_int_equal(cdem_cmd_plot_series(7, argv2), 0);
    assert_true(file_size(pdf) > 500);
    char *argv3[] = {"plot-series", h5, "--y", "nonsense", "-o", pdf};
    assert_int_equal(cdem_cmd_plot_series(6, argv3), 1);
    char *argv4[] = {"plot-series", h5, "--y", "contacts"};
    assert_int_equal(cdem_cmd_plot_series(4, argv4), 2);
    /* any column as x (issue 18: --x axial_strain was refused): the stress-strain layout */
    char *argv7[] = {"plot-series", h5,        "--y", "kinetic_energy", "--x", "axial_strain", "-o",
                     png,           "--width", "800", "--height",       "500"};
    assert_int_equal(cdem_cmd_plot_series(12, argv7), 0);
    img = cairo_image_surface_create_from_png(png);
    assert_int_equal(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
    for (int k = 0; k < NS; k++)
        x[k] = 0.002 * k;
    p.fix_y = 0;
    assert_int_equal(cdem_plot_layout_compute(&p, 0, 0, 800, 500, &lay, &err), CDEM_OK);
    cdem_plot_to_device(&lay, 0.012, 36.0, &dx, &dy); /* sample k = 6 */
    on = pixel(img, dx, dy);
    assert_true((on & 255) > ((on >> 16) & 255) + 60);
    cairo_surface_destroy(img);
    char *argv8[] = {"plot-series", h5, "--y", "contacts", "--x", "nonsense", "-o", pdf};
    assert_int_equal(cdem_cmd_plot_series(8, argv8), 2);
}

/* fontconfig, which cairo's text uses, keeps a process-lifetime configuration that only
 * FcFini releases (as in test_render.c). LeakSanitizer reads this hook in the asan build. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) {
    return "leak:libfontconfig.so\n";
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plot_nice_ticks),
        cmocka_unit_test(test_plot_layout_range_and_aspect),
        cmocka_unit_test(test_plot_thirty_series_differ),
        cmocka_unit_test(test_plot_legend_avoids_the_data),
        cmocka_unit_test(test_plot_errors_name_the_problem),
        cmocka_unit_test(test_plot_column_extraction),
        cmocka_unit_test(test_plot_series_command_draws_the_line),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    cairo_debug_reset_static_data(); /* drop cairo's font caches before LeakSanitizer looks */
    return failed;
}
