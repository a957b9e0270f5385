/* Tests of repose.[ch] (angle of repose of the free surface) and the repose subcommand. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cairo.h>
#include <cmocka.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

static double convex_surface(double x) { /* 12 degrees from the crest, then 50 degrees */
    double y = 2500.0 - fmax(0.0, x - 1000.0) * tan(12 * deg);
    if (x > 4500.0)
        y = 2500.0 - 3500.0 * tan(12 * deg) - (x - 4500.0) * tan(50 * deg);
    return fmax(200.0, y);
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
    p.mode = CDEM_MODE_REPOSE;
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

/* A straight slope is a good fit: narrow confidence interval, halves alike, no flags. */
static void test_repose_straight_slope_is_a_good_fit(void **state) {
    (void)state;
    for (unsigned long seed = 1; seed <= 3; seed++) {
        cdem_state s = {0};
        make_pile(&s, wedge_surface, seed);
        cdem_repose_result r;
        cdem_error err;
        assert_int_equal(cdem_repose_measure(&s, &r, &err), CDEM_OK);
        const cdem_repose_flank *f = &r.flank[1];
        assert_int_equal(r.poor, 0);
        assert_int_equal(f->poor, 0);
        assert_near(r.r_max, 125.0, 1e-9);
        assert_true(f->angle_ci_deg > 0 && f->angle_ci_deg < CDEM_REPOSE_MAX_CI_DEG);
        assert_near(f->angle_upper_deg, 30.0, 6.0);
        assert_near(f->angle_lower_deg, 30.0, 6.0);
        assert_true(fabs(f->angle_upper_deg - f->angle_lower_deg) < CDEM_REPOSE_MAX_BEND_DEG);
        char why[256] = "x";
        cdem_repose_poor_text(f, r.r_max, why, sizeof why);
        assert_string_equal(why, "");
        cdem_state_free(&s);
    }
}

/* A convex slope (12 degrees below the crest, then 50) is flagged: its halves differ, and
 * the text says so with both angles. */
static void test_repose_curved_slope_is_a_poor_fit(void **state) {
    (void)state;
    cdem_state s = {0};
    make_pile(&s, convex_surface, 5);
    cdem_repose_result r;
    cdem_error err;
    assert_int_equal(cdem_repose_measure(&s, &r, &err), CDEM_OK);
    const cdem_repose_flank *f = &r.flank[1];
    assert_true(f->poor & CDEM_REPOSE_CURVED);
    assert_true(r.poor & CDEM_REPOSE_CURVED);
    assert_true(f->angle_lower_deg - f->angle_upper_deg > CDEM_REPOSE_MAX_BEND_DEG);
    char why[512];
    cdem_repose_poor_text(f, r.r_max, why, sizeof why);
    assert_non_null(strstr(why, "the slope is curved: upper half "));
    char tiny[8];
    cdem_repose_poor_text(f, r.r_max, tiny, sizeof tiny); /* truncated, terminated */
    assert_int_equal(strlen(tiny), 7);
    /* too few columns: a short steep step */
    cdem_repose_flank few = {.n = 4, .poor = CDEM_REPOSE_FEW};
    cdem_repose_poor_text(&few, 125.0, why, sizeof why);
    assert_string_equal(why, "only 4 columns on the slope, fewer than 6");
    cdem_state_free(&s);
}

static void test_repose_motion_between_increments(void **state) {
    (void)state;
    cdem_state a = {0}, b = {0};
    cdem_error err;
    assert_int_equal(cdem_state_init(&a, 16, 0, &err), CDEM_OK);
    for (int i = 0; i < 4; i++)
        cdem_state_append(&a, -1, 100.0 * i, 50.0, 50.0, 1.0, 1, 0, 0, NULL, &err);
    cdem_state_append(&a, -1, -50.0, -50.0, 50.0, 1.0, 0, CDEM_FLAG_WALL, 0, NULL, &err);
    assert_int_equal(cdem_state_copy(&b, &a, &err), CDEM_OK);
    b.x[0] += 3.0; /* moved 3 m and 4 m: 5 m */
    b.y[0] += 4.0;
    b.x[4] += 1000.0; /* a wall does not count */
    unsigned char keep[5] = {1, 1, 1, 0, 1};
    cdem_state_compact(&b, keep, NULL); /* element 3 left the model */
    cdem_repose_motion m;
    assert_int_equal(cdem_repose_motion_between(&a, &b, &m, &err), CDEM_OK);
    assert_int_equal(m.n_before, 4);
    assert_int_equal(m.n_after, 3);
    assert_int_equal(m.n_matched, 3);
    assert_near(m.max, 5.0, 1e-12);
    assert_near(m.mean, 5.0 / 3.0, 1e-12);
    cdem_repose_settling v;
    double steady[3] = {30.0, 30.5, 31.9}, drifting[3] = {30.0, 31.0, 32.1};
    cdem_repose_motion still = {.mean = 1.0, .n_matched = 3, .n_before = 3, .n_after = 3};
    cdem_repose_settled(steady, 3, &still, 125.0, &v);
    assert_true(v.stable && v.at_rest);
    assert_near(v.angle_min, 30.0, 0);
    assert_near(v.angle_max, 31.9, 0);
    cdem_repose_settled(drifting, 3, &still, 125.0, &v);
    assert_false(v.stable);
    cdem_repose_settled(steady, 3, &m, 125.0, &v); /* one element lost: not at rest */
    assert_false(v.at_rest);
    still.mean = 1.25; /* 1 % of the largest radius: moving */
    cdem_repose_settled(steady, 3, &still, 125.0, &v);
    assert_false(v.at_rest);
    double gap[2] = {30.0, NAN};
    cdem_repose_settled(gap, 2, &still, 125.0, &v);
    assert_false(v.stable);
    cdem_repose_settled(steady, 1, &still, 125.0, &v); /* one increment: not judged stable */
    assert_false(v.stable);
    b.id[0] = -1;
    assert_int_equal(cdem_repose_motion_between(&a, &b, &m, &err), CDEM_ERR_INVALID);
    assert_non_null(strstr(err.msg, "ids must be >= 0"));
    cdem_state_free(&a);
    cdem_state_free(&b);
}

/* Runs the command with stdout and stderr to files; returns its status, the texts in out
 * and errs. */
static int run_repose_captured(char **argv, int argc, char *out, size_t n_out, char *errs,
                               size_t n_errs) {
    char path_out[512], path_err[512];
    scratch_path(path_out, sizeof path_out, "repose-out.txt");
    scratch_path(path_err, sizeof path_err, "repose-err.txt");
    fflush(stdout);
    fflush(stderr);
    int so = dup(1), se = dup(2);
    int fo = open(path_out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int fe = open(path_err, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    assert_true(so >= 0 && se >= 0 && fo >= 0 && fe >= 0);
    dup2(fo, 1);
    dup2(fe, 2);
    int rc = cdem_cmd_plot_repose(argc, argv);
    fflush(stdout);
    fflush(stderr);
    dup2(so, 1);
    dup2(se, 2);
    close(fo);
    close(fe);
    close(so);
    close(se);
    const char *paths[2] = {path_out, path_err};
    char *texts[2] = {out, errs};
    size_t sizes[2] = {n_out, n_errs};
    for (int k = 0; k < 2; k++) {
        FILE *f = fopen(paths[k], "r");
        assert_non_null(f);
        size_t got = fread(texts[k], 1, sizes[k] - 1, f);
        texts[k][got] = 0;
        fclose(f);
    }
    return rc;
}

/* A run file of the pile: increment 0 ends the equilibration, then `n` increments of the
 * collapse 60 s apart, in which the free elements move down by drop[k] m (cumulative); its
 * boundary.mode is `mode`. */
static void write_run_of_mode(const char *h5, const cdem_state *pile, const double *drop, int n,
                              cdem_mode mode) {
    cdem_params p;
    cdem_params_defaults(&p);
    p.mode = mode;
    cdem_run_meta meta = {&p, "", "repose test", "0", "test", 0};
    cdem_h5_writer *w;
    cdem_error err;
    assert_int_equal(cdem_h5_writer_create(h5, &meta, &w, &err), CDEM_OK);
    for (int k = 0; k <= n; k++) {
        cdem_state s = {0};
        assert_int_equal(cdem_state_copy(&s, pile, &err), CDEM_OK);
        for (size_t i = 0; i < s.n; i++)
            if (!(s.flags[i] & CDEM_FLAG_WALL) && k > 0)
                s.y[i] -= drop[k - 1] * s.y[i] / 3000.0; /* a slope that sags */
        cdem_increment_info info = {.number = k,
                                    .step = 100 * k,
                                    .time = 60.0 * k,
                                    .phase = k ? CDEM_PHASE_DEFORMATION : CDEM_PHASE_EQUILIBRATION,
                                    .sea_level = NAN,
                                    .n_elements = (int64_t)s.n};
        assert_int_equal(cdem_h5_writer_write_increment(w, &info, &s, &err), CDEM_OK);
        cdem_state_free(&s);
    }
    assert_int_equal(cdem_h5_writer_close(w, &err), CDEM_OK);
}

/* write_run_of_mode of a repose-collapse run. */
static void write_collapse(const char *h5, const cdem_state *pile, const double *drop, int n) {
    write_run_of_mode(h5, pile, drop, n, CDEM_MODE_REPOSE);
}

/* The command judges the settling over the last third of the run: a pile that still
 * sags is "still moving" (with a warning on stderr), one that stopped is "settled"; a poor
 * fit is said on stdout and stderr. */
static void test_repose_command_says_when_moving_or_poor(void **state) {
    (void)state;
    char h5[512];
    scratch_path(h5, sizeof h5, "repose-collapse.h5");
    cdem_state pile = {0};
    make_pile(&pile, wedge_surface, 3);
    char out[8192], errs[4096];
    char *argv[] = {"repose", h5};
    double sagging[9] = {0, 50, 100, 150, 200, 250, 300, 350, 400};
    write_collapse(h5, &pile, sagging, 9);
    assert_int_equal(run_repose_captured(argv, 2, out, sizeof out, errs, sizeof errs), 0);
    assert_non_null(strstr(out, "right flank: good fit"));
    /* the flank's angle and its confidence half-width, each with its unit */
    const char *flank = strstr(out, "  right flank: ");
    assert_non_null(flank);
    char *after;
    strtod(flank + strlen("  right flank: "), &after);
    assert_true(!strncmp(after, " deg +- ", 8));
    strtod(after + 8, &after);
    assert_true(!strncmp(after, " deg (95 %), ", 13));
    assert_non_null(strstr(out, "motion in the last increment (8 to 9): mean "));
    assert_non_null(strstr(out, ": moving (the limit is 1 % of the largest radius, 125 m)"));
    assert_non_null(strstr(out, "angle over the last third of the run (increments 6 to 9, "
                                "360 to 540 s)"));
    assert_non_null(strstr(out, "slope: still moving"));
    assert_null(strstr(out, "at rest since"));
    assert_non_null(strstr(errs, "warning: "));
    assert_non_null(strstr(errs, "the slope is still moving at increment 9"));
    double stopped[9] = {0, 50, 100, 150, 200, 200, 200, 200, 200};
    write_collapse(h5, &pile, stopped, 9);
    assert_int_equal(run_repose_captured(argv, 2, out, sizeof out, errs, sizeof errs), 0);
    assert_non_null(strstr(out, ": at rest (the limit"));
    assert_non_null(
        strstr(out, "at rest since increment 6 (360 s, 360 s after the end of equilibration)"));
    assert_non_null(strstr(out, "deg: stable (within 2 deg)"));
    assert_non_null(strstr(out, "slope: settled"));
    assert_non_null(strstr(out, "0 left the model"));
    assert_string_equal(errs, "");
    char *argv_equil[] = {"repose", h5, "--increment", "0"};
    assert_int_equal(run_repose_captured(argv_equil, 4, out, sizeof out, errs, sizeof errs), 0);
    assert_non_null(strstr(out, "settling: not judged (increment 0 is not after the end"));
    cdem_state_free(&pile);
    cdem_state convex = {0};
    make_pile(&convex, convex_surface, 5);
    write_collapse(h5, &convex, stopped, 9);
    assert_int_equal(run_repose_captured(argv, 2, out, sizeof out, errs, sizeof errs), 0);
    assert_non_null(strstr(out, "right flank: poor fit: the slope is curved"));
    assert_non_null(strstr(errs, "poor fit of the right flank: the slope is curved"));
    cdem_state_free(&convex);
    const char *names[4] = {"repose-collapse.h5", "repose-collapse.xmf", "repose-out.txt",
                            "repose-err.txt"};
    for (int k = 0; k < 4; k++) {
        char path[512];
        scratch_path(path, sizeof path, names[k]);
        remove(path);
    }
}

/* The spread of several runs' angles: mean, sample standard deviation, standard error and
 * range, runs without a measure (NaN) left out. */
static void test_repose_spread_of_angles(void **state) {
    (void)state;
    const double angles[4] = {30.0, NAN, 34.0, 32.0};
    cdem_repose_spread sp;
    cdem_error err;
    assert_int_equal(cdem_repose_spread_of(angles, 4, &sp, &err), CDEM_OK);
    assert_int_equal(sp.n, 3);
    assert_near(sp.mean_deg, 32.0, 1e-12);
    assert_near(sp.sd_deg, 2.0, 1e-12); /* sqrt((4 + 0 + 4) / 2) */
    assert_near(sp.se_deg, 2.0 / sqrt(3.0), 1e-12);
    assert_near(sp.min_deg, 30.0, 0);
    assert_near(sp.max_deg, 34.0, 0);
    assert_int_equal(cdem_repose_spread_of(angles, 1, &sp, &err), CDEM_OK); /* one run */
    assert_int_equal(sp.n, 1);
    assert_near(sp.mean_deg, 30.0, 0);
    assert_true(isnan(sp.sd_deg) && isnan(sp.se_deg));
    assert_int_equal(cdem_repose_spread_of(angles + 1, 1, &sp, &err), CDEM_OK); /* none */
    assert_int_equal(sp.n, 0);
    assert_true(isnan(sp.mean_deg) && isnan(sp.min_deg));
}

/* The angle printed first by a repose report. */
static double reported_angle(const char *out) {
    const char *p = strstr(out, "angle of repose = ");
    assert_non_null(p);
    return strtod(p + strlen("angle of repose = "), NULL);
}

/* The number after `key` in text (NaN when key is not there). */
static double number_after(const char *text, const char *key) {
    const char *p = text ? strstr(text, key) : NULL;
    return p ? strtod(p + strlen(key), NULL) : NAN;
}

/* Several runs of one material: each reported under its name, then the mean, standard
 * deviation and range of those measured with a good fit (issue 46, item 6), the mean with the
 * poor fits beside it (--include-poor-fits makes that the result); a run that cannot be read
 * is named on stderr, left out of the count and makes the exit status 1; -o takes one run. */
static void test_repose_command_several_runs(void **state) {
    (void)state;
    char h5a[512], h5b[512], h5c[512], missing[512];
    scratch_path(h5a, sizeof h5a, "repose-packing-a.h5");
    scratch_path(h5b, sizeof h5b, "repose-packing-b.h5");
    scratch_path(h5c, sizeof h5c, "repose-packing-c.h5");
    scratch_path(missing, sizeof missing, "repose-packing-missing.h5");
    remove(missing);
    double stopped[9] = {0, 50, 100, 150, 200, 200, 200, 200, 200};
    cdem_state straight = {0}, convex = {0}, other = {0};
    make_pile(&straight, wedge_surface, 3);
    make_pile(&convex, convex_surface, 5);
    make_pile(&other, wedge_surface, 8);
    write_collapse(h5a, &straight, stopped, 9);
    write_collapse(h5b, &convex, stopped, 9);
    write_collapse(h5c, &other, stopped, 9);
    static char out[65536];
    char errs[4096];
    char *one_a[] = {"repose", h5a}, *one_b[] = {"repose", h5b}, *one_c[] = {"repose", h5c};
    assert_int_equal(run_repose_captured(one_a, 2, out, sizeof out, errs, sizeof errs), 0);
    const double a = reported_angle(out);
    assert_int_equal(run_repose_captured(one_b, 2, out, sizeof out, errs, sizeof errs), 0);
    const double b = reported_angle(out);
    assert_non_null(strstr(out, "poor fit: the slope is curved"));
    assert_int_equal(run_repose_captured(one_c, 2, out, sizeof out, errs, sizeof errs), 0);
    const double c = reported_angle(out);
    assert_non_null(strstr(out, "good fit (a straight slope)"));
    assert_true(fabs(a - b) > 1.0 && fabs(a - c) > 0.05); /* different slopes: a spread */

    /* two good fits and a poor one: the mean is the good fits', the poor fit's beside */
    char *three[] = {"repose", h5a, h5b, h5c};
    assert_int_equal(run_repose_captured(three, 4, out, sizeof out, errs, sizeof errs), 0);
    char expect[1024];
    snprintf(expect, sizeof expect, "run %s:\nangle of repose = ", h5a);
    assert_non_null(strstr(out, expect));
    snprintf(expect, sizeof expect, "\nrun %s:\nangle of repose = ", h5b);
    assert_non_null(strstr(out, expect));
    const char *sum = strstr(out, "\nover 2 runs: angle of repose ");
    assert_non_null(sum);
    assert_near(number_after(sum, "angle of repose "), 0.5 * (a + c), 0.006);
    /* a and c as printed (2 decimals): the spread's numbers agree to within their rounding */
    assert_near(number_after(sum, "standard deviation "), fabs(a - c) / sqrt(2.0), 0.011);
    assert_near(number_after(sum, "standard error of the mean "), fabs(a - c) / 2.0, 0.011);
    const char *with = strstr(sum, "  left out: 1 poor fit (--include-poor-fits counts them); "
                                   "with them:\n  over 3 runs: angle of repose ");
    assert_non_null(with);
    assert_near(number_after(with, "angle of repose "), (a + b + c) / 3.0, 0.006);
    assert_non_null(strstr(sum, "good fits: 2 of 3 runs measured; settled: 3 of 3 runs measured"));

    /* --include-poor-fits: the mean of all three, the good fits' beside */
    char *counted[] = {"repose", h5a, h5b, h5c, "--include-poor-fits"};
    assert_int_equal(run_repose_captured(counted, 5, out, sizeof out, errs, sizeof errs), 0);
    sum = strstr(out, "\nover 3 runs: angle of repose ");
    assert_non_null(sum);
    assert_near(number_after(sum, "angle of repose "), (a + b + c) / 3.0, 0.006);
    with = strstr(sum, "  poor fits counted (--include-poor-fits): 1; the good fits alone:\n"
                       "  over 2 runs: angle of repose ");
    assert_non_null(with);
    assert_near(number_after(with, "angle of repose "), 0.5 * (a + c), 0.006);

    /* only poor fits: no angle of repose, exit 1; with the option their mean */
    char h5d[512];
    scratch_path(h5d, sizeof h5d, "repose-packing-d.h5");
    cdem_state convex2 = {0};
    make_pile(&convex2, convex_surface, 9);
    write_collapse(h5d, &convex2, stopped, 9);
    cdem_state_free(&convex2);
    char *poor_two[] = {"repose", h5b, h5d};
    assert_int_equal(run_repose_captured(poor_two, 3, out, sizeof out, errs, sizeof errs), 1);
    assert_non_null(strstr(out, "no good fit among the 2 runs measured: no angle of repose"));
    assert_non_null(strstr(errs, "cdem-strain repose: no good fit among the 2 runs: no angle of "
                                 "repose (--include-poor-fits counts the poor fits)"));
    char *poor_counted[] = {"repose", h5b, h5d, "--include-poor-fits"};
    assert_int_equal(run_repose_captured(poor_counted, 4, out, sizeof out, errs, sizeof errs), 0);
    assert_non_null(strstr(out, "\nover 2 runs: angle of repose "));

    /* a missing run: counted neither in the mean nor in "over N runs" */
    char *with_missing[] = {"repose", h5a, missing, h5c};
    assert_int_equal(run_repose_captured(with_missing, 4, out, sizeof out, errs, sizeof errs), 1);
    sum = strstr(out, "\nover 2 runs: angle of repose ");
    assert_non_null(sum);
    assert_near(number_after(sum, "angle of repose "), 0.5 * (a + c), 0.006);
    assert_non_null(strstr(out, "good fits: 2 of 2 runs measured"));
    assert_non_null(strstr(out, "not measured: 1 of 3 runs given"));
    assert_null(strstr(out, "over 3 runs"));
    snprintf(expect, sizeof expect, "cdem-strain repose: %s: cannot open", missing);
    assert_non_null(strstr(errs, expect));

    char missing2[512];
    scratch_path(missing2, sizeof missing2, "repose-packing-missing-2.h5");
    char *none[] = {"repose", missing, missing2};
    assert_int_equal(run_repose_captured(none, 3, out, sizeof out, errs, sizeof errs), 1);
    assert_non_null(strstr(out, "over 2 runs given: none measured"));

    char png[512];
    scratch_path(png, sizeof png, "repose-packings.png");
    char *drawn[] = {"repose", h5a, h5b, "-o", png};
    assert_int_equal(run_repose_captured(drawn, 5, out, sizeof out, errs, sizeof errs), 2);
    assert_non_null(strstr(errs, "-o draws one run: give one RUN.h5 with -o"));
    assert_int_equal(access(png, F_OK), -1);
    char *one_counted[] = {"repose", h5a, "--include-poor-fits"};
    assert_int_equal(run_repose_captured(one_counted, 3, out, sizeof out, errs, sizeof errs), 2);
    assert_non_null(strstr(errs, "--include-poor-fits counts poor fits in the mean of several "
                                 "runs: give two or more RUN.h5"));
    cdem_state_free(&straight);
    cdem_state_free(&convex);
    cdem_state_free(&other);
    const char *names[10] = {"repose-packing-a.h5",  "repose-packing-a.xmf", "repose-packing-b.h5",
                             "repose-packing-b.xmf", "repose-packing-c.h5",  "repose-packing-c.xmf",
                             "repose-packing-d.h5",  "repose-packing-d.xmf", "repose-out.txt",
                             "repose-err.txt"};
    for (int k = 0; k < 10; k++) {
        char path[512];
        scratch_path(path, sizeof path, names[k]);
        remove(path);
    }
}

/* Each run counts once (issue 46, item 6): one file given twice, also by another path (with
 * ./ in it, through a symbolic link), is refused before anything is measured; a run that is
 * not a repose collapse is not measured, not counted, and makes the exit status 1. */
static void test_repose_command_counts_each_repose_run_once(void **state) {
    (void)state;
    char h5a[512], h5c[512], det[512], link_path[512], dotted[600];
    scratch_path(h5a, sizeof h5a, "repose-once-a.h5");
    scratch_path(h5c, sizeof h5c, "repose-once-c.h5");
    scratch_path(det, sizeof det, "repose-once-detachment.h5");
    scratch_path(link_path, sizeof link_path, "repose-once-link.h5");
    double stopped[9] = {0, 50, 100, 150, 200, 200, 200, 200, 200};
    cdem_state straight = {0}, other = {0};
    make_pile(&straight, wedge_surface, 3);
    make_pile(&other, wedge_surface, 8);
    write_collapse(h5a, &straight, stopped, 9);
    write_collapse(h5c, &other, stopped, 9);
    write_run_of_mode(det, &straight, stopped, 9, CDEM_MODE_DETACHMENT);
    remove(link_path);
    assert_int_equal(symlink(h5a, link_path), 0);
    const char *slash = strrchr(h5a, '/');
    assert_non_null(slash);
    snprintf(dotted, sizeof dotted, "%.*s/./%s", (int)(slash - h5a), h5a, slash + 1);
    static char out[65536];
    char errs[4096], expect[2048];

    char *thrice[] = {"repose", h5a, h5a, h5a};
    assert_int_equal(run_repose_captured(thrice, 4, out, sizeof out, errs, sizeof errs), 2);
    snprintf(expect, sizeof expect,
             "%s (run 2) is the same file as %s (run 1): each run counts once; give each file "
             "once",
             h5a, h5a);
    assert_non_null(strstr(errs, expect));
    assert_string_equal(out, ""); /* nothing measured */
    char *by_dot[] = {"repose", h5a, h5c, dotted};
    assert_int_equal(run_repose_captured(by_dot, 4, out, sizeof out, errs, sizeof errs), 2);
    snprintf(expect, sizeof expect, "%s (run 3) is the same file as %s (run 1)", dotted, h5a);
    assert_non_null(strstr(errs, expect));
    char *by_link[] = {"repose", link_path, h5c, h5a};
    assert_int_equal(run_repose_captured(by_link, 4, out, sizeof out, errs, sizeof errs), 2);
    snprintf(expect, sizeof expect, "%s (run 3) is the same file as %s (run 1)", h5a, link_path);
    assert_non_null(strstr(errs, expect));

    /* a detachment run: named, not measured, not counted, exit 1 */
    char *one_det[] = {"repose", det};
    assert_int_equal(run_repose_captured(one_det, 2, out, sizeof out, errs, sizeof errs), 1);
    snprintf(expect, sizeof expect,
             "cdem-strain repose: %s: a 'detachment' run (boundary.mode = detachment), not a "
             "repose-collapse run (boundary.mode = repose): not measured",
             det);
    assert_non_null(strstr(errs, expect));
    assert_null(strstr(out, "angle of repose = "));
    char *mixed[] = {"repose", h5a, det, h5c};
    assert_int_equal(run_repose_captured(mixed, 4, out, sizeof out, errs, sizeof errs), 1);
    assert_non_null(strstr(errs, expect));
    assert_non_null(strstr(out, "\nover 2 runs: angle of repose "));
    assert_non_null(strstr(out, "not measured: 1 of 3 runs given"));
    cdem_state_free(&straight);
    cdem_state_free(&other);
    const char *names[9] = {"repose-once-a.h5",
                            "repose-once-a.xmf",
                            "repose-once-c.h5",
                            "repose-once-c.xmf",
                            "repose-once-detachment.h5",
                            "repose-once-detachment.xmf",
                            "repose-once-link.h5",
                            "repose-out.txt",
                            "repose-err.txt"};
    for (int k = 0; k < 9; k++) {
        char path[512];
        scratch_path(path, sizeof path, names[k]);
        remove(path);
    }
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
        cmocka_unit_test(test_repose_straight_slope_is_a_good_fit),
        cmocka_unit_test(test_repose_curved_slope_is_a_poor_fit),
        cmocka_unit_test(test_repose_motion_between_increments),
        cmocka_unit_test(test_repose_command_says_when_moving_or_poor),
        cmocka_unit_test(test_repose_spread_of_angles),
        cmocka_unit_test(test_repose_command_several_runs),
        cmocka_unit_test(test_repose_command_counts_each_repose_run_once),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    cairo_debug_reset_static_data(); /* drop cairo's font caches before LeakSanitizer looks */
    return failed;
}
