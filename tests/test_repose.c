/* Tests of repose.[ch] (angle of repose of the free surface) and the repose subcommand. */
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

#include "analysis_fixtures.h"
#include "assert_near.h"
#include "cmd_plot.h"
#include "h5format.h"
#include "params.h"
#include "render.h"
#include "repose.h"
#include "scratch.h"

static const double deg = 3.14159265358979323846 / 180.0;

/* Surface heights (m) of the test piles. */
static double wedge_surface(double x) { /* flat crest 2500 m, 30 degree slope, 200 m toe */
    return fmax(200.0, fmin(2500.0, 200.0 + (7000.0 - x) * tan(30 * deg)));
}

static double mound_surface(double x) { /* 30 degree cone on both sides, crest at 4000 m */
    return fmax(150.0, 2400.0 - fabs(x - 4000.0) * tan(30 * deg));
}

/* A dense random packing (radii 50..125 m) trimmed to lie under surface(x), plus the base
 * wall row and a tall left wall column (which must be ignored). */
static void make_pile(cdem_state *s, double (*surface)(double), unsigned long seed) {
    make_packing(s, 2000, 8000.0, 3000.0, seed);
    unsigned char *keep = malloc(s->n);
    assert_non_null(keep);
    for (size_t i = 0; i < s->n; i++)
        keep[i] = (s->flags[i] & CDEM_FLAGS_BOUNDARY) || s->y[i] + s->radius[i] <= surface(s->x[i]);
    cdem_state_compact(s, keep, NULL);
    free(keep);
    cdem_error err;
    for (double y = 0; y < 4000.0; y += 100.0)
        assert_int_equal(
            cdem_state_append(s, -1, -60.0, y, 50.0, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err),
            CDEM_OK);
}

static void test_repose_wedge_30_degrees(void **state) {
    (void)state;
    for (unsigned long seed = 1; seed <= 3; seed++) {
        cdem_state s = {0};
        make_pile(&s, wedge_surface, seed);
        cdem_repose_result r;
        cdem_error err;
        assert_int_equal(cdem_repose_measure(&s, &r, &err), CDEM_OK);
        assert_near(r.angle_deg, 30.0, 1.5);
        assert_near(r.column_width, 250.0, 1e-9);
        assert_int_equal(r.flank[0].n, 0); /* the crest is at the left: one flank */
        assert_true(r.flank[1].n >= 8);
        assert_true(r.flank[1].slope < 0);
        /* the fitted elements lie on the slope, not on the crest or the toe */
        assert_true(r.flank[1].x_first > 3000.0 && r.flank[1].x_last < 7000.0);
        cdem_state_free(&s);
    }
}

static void test_repose_mound_two_flanks(void **state) {
    (void)state;
    cdem_state s = {0};
    make_pile(&s, mound_surface, 7);
    cdem_repose_result r;
    cdem_error err;
    assert_int_equal(cdem_repose_measure(&s, &r, &err), CDEM_OK);
    assert_true(r.flank[0].n >= 4 && r.flank[1].n >= 4);
    assert_true(r.flank[0].slope > 0 && r.flank[1].slope < 0);
    assert_near(r.flank[0].angle_deg, 30.0, 2.0);
    assert_near(r.flank[1].angle_deg, 30.0, 2.0);
    assert_near(r.angle_deg, 30.0, 1.5);
    cdem_state_free(&s);
}

static void test_repose_bad_states_messages(void **state) {
    (void)state;
    cdem_state s = {0};
    cdem_error err;
    cdem_repose_result r;
    assert_int_equal(cdem_state_init(&s, 64, 0, &err), CDEM_OK);
    for (int i = 0; i < 10; i++)
        cdem_state_append(&s, -1, 100.0 * i, -50.0, 50.0, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err);
    assert_int_equal(cdem_repose_measure(&s, &r, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "no free"));
    for (int i = 0; i < 20; i++) /* a flat layer: no slope */
        cdem_state_append(&s, -1, 100.0 * i, 50.0, 50.0, 1.0, 1, 0, 0, NULL, &err);
    assert_int_equal(cdem_repose_measure(&s, &r, &err), CDEM_ERR_NOTFOUND);
    assert_non_null(strstr(err.msg, "need at least 2"));
    cdem_state_free(&s);
}

static void test_repose_command_prints_and_draws(void **state) {
    (void)state;
    char h5[512], png[512];
    snprintf(h5, sizeof h5, "%s/repose.h5", scratch_root());
    snprintf(png, sizeof png, "%s/repose.png", scratch_root());
    cdem_state s = {0};
    make_pile(&s, wedge_surface, 11);
    cdem_params p;
    cdem_params_defaults(&p);
    cdem_run_meta meta = {&p, "", "repose test", "0", "test", 0};
    cdem_h5_writer *w;
    cdem_error err;
    assert_int_equal(cdem_h5_writer_create(h5, &meta, &w, &err), CDEM_OK);
    cdem_increment_info info = {.number = 0, .sea_level = NAN, .n_elements = (int64_t)s.n};
    assert_int_equal(cdem_h5_writer_write_increment(w, &info, &s, &err), CDEM_OK);
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
    cdem_repose_result r;
    assert_int_equal(cdem_repose_measure(&s, &r, &err), CDEM_OK);
    char *argv[] = {"repose", h5, "--increment", "last", "-o", png, "--width", "800"};
    assert_int_equal(cdem_cmd_plot_repose(8, argv), 0);
    cairo_surface_t *img = cairo_image_surface_create_from_png(png);
    assert_int_equal(cairo_surface_status(img), CAIRO_STATUS_SUCCESS);
    assert_int_equal(cairo_image_surface_get_width(img), 800);
    /* the fitted line is drawn in black where the renderer's layout maps it */
    cdem_render_options o;
    cdem_render_options_default(&o);
    o.width = 800;
    cdem_render_scene sc = {.state = &s, .label = "label"};
    int h;
    assert_int_equal(cdem_render_auto_height(&sc, &o, &h, &err), CDEM_OK);
    assert_int_equal(cairo_image_surface_get_height(img), h);
    cdem_render_layout lay;
    assert_int_equal(cdem_render_layout_compute(&sc, &o, 800, h, &lay, &err), CDEM_OK);
    const cdem_repose_flank *f = &r.flank[1];
    double xm = 0.5 * (f->x_first + f->x_last), dx, dy;
    cdem_render_layout_to_device(&lay, xm, f->intercept + f->slope * xm, &dx, &dy);
    const unsigned char *d = cairo_image_surface_get_data(img);
    uint32_t px =
        ((const uint32_t *)(const void *)(d + (size_t)(int)dy *
                                                  cairo_image_surface_get_stride(img)))[(int)dx];
    assert_true(((px >> 16) & 255) < 90 && ((px >> 8) & 255) < 90 && (px & 255) < 90);
    cairo_surface_destroy(img);
    char *argv2[] = {"repose", h5, "--increment", "99"};
    assert_int_equal(cdem_cmd_plot_repose(4, argv2), 1);
    char *argv3[] = {"repose"};
    assert_int_equal(cdem_cmd_plot_repose(1, argv3), 2);
    cdem_state_free(&s);
}

/* fontconfig, which cairo's text uses, keeps a process-lifetime configuration that only
 * FcFini releases (as in test_render.c). LeakSanitizer reads this hook in the asan build. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) {
    return "leak:libfontconfig.so\n";
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_repose_wedge_30_degrees),
        cmocka_unit_test(test_repose_mound_two_flanks),
        cmocka_unit_test(test_repose_bad_states_messages),
        cmocka_unit_test(test_repose_command_prints_and_draws),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    cairo_debug_reset_static_data(); /* drop cairo's font caches before LeakSanitizer looks */
    return failed;
}
