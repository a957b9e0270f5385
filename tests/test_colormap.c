/* Tests of analysis/colormap: end and middle colours of both scales, white at zero for the
 * signed scale, monotone and smooth interpolation, positions and limits, name parsing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "colormap.h"

static void assert_colour(cdem_rgba c, double r, double g, double b) {
    assert_true(fabs(c.r - r) < 1e-12);
    assert_true(fabs(c.g - g) < 1e-12);
    assert_true(fabs(c.b - b) < 1e-12);
    assert_true(c.a == 1.0);
}

static void test_colormap_magnitude_ends_and_middle(void **state) {
    (void)state;
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.0), 0, 0, 1);  /* blue low */
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.5), 0, 1, 0);  /* green */
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 1.0), 1, 0, 0);  /* red high */
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, -3.0), 0, 0, 1); /* clamped */
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 7.0), 1, 0, 0);
    /* halfway between the blue and cyan stops */
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.125), 0, 0.5, 1);
}

static void test_colormap_signed_ends_and_white_at_zero(void **state) {
    (void)state;
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 0.0), 0, 0, 1);
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 0.5), 1, 1, 1);
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 1.0), 1, 0, 0);
    /* zero maps to the middle (white) whatever the asymmetry of the limits */
    assert_true(cdem_colormap_position(CDEM_COLORMAP_SIGNED, 0.0, -3.0, 5.0) == 0.5);
    assert_true(cdem_colormap_position(CDEM_COLORMAP_SIGNED, 0.0, -1e-3, 2e-2) == 0.5);
    assert_colour(cdem_colormap_eval(CDEM_COLORMAP_SIGNED,
                                     cdem_colormap_position(CDEM_COLORMAP_SIGNED, 0, -2, 9)),
                  1, 1, 1);
    double lo, hi;
    cdem_colormap_limits(CDEM_COLORMAP_SIGNED, -3.0, 5.0, &lo, &hi);
    assert_true(lo == -5.0 && hi == 5.0);
    cdem_colormap_limits(CDEM_COLORMAP_MAGNITUDE, -3.0, 5.0, &lo, &hi);
    assert_true(lo == -3.0 && hi == 5.0);
    /* halfway to the red end: white mixed with red by sin(pi/4) */
    cdem_rgba c = cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 0.75);
    double w = sin(M_PI / 4.0);
    assert_colour(c, 1.0, 1.0 - w, 1.0 - w);
}

static double hue_deg(cdem_rgba c) {
    double mx = fmax(c.r, fmax(c.g, c.b)), mn = fmin(c.r, fmin(c.g, c.b));
    double d = mx - mn, h;
    if (d <= 0)
        return 0;
    if (mx == c.r)
        h = fmod((c.g - c.b) / d, 6.0);
    else if (mx == c.g)
        h = (c.b - c.r) / d + 2.0;
    else
        h = (c.r - c.g) / d + 4.0;
    h *= 60.0;
    return h < 0 ? h + 360.0 : h;
}

static void test_colormap_monotone_and_smooth(void **state) {
    (void)state;
    const int n = 1000;
    cdem_rgba prev_m = cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, 0.0);
    cdem_rgba prev_s = cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 0.0);
    double prev_h = hue_deg(prev_m);
    assert_true(fabs(prev_h - 240.0) < 1e-9);
    for (int k = 1; k <= n; k++) {
        double t = (double)k / n;
        cdem_rgba m = cdem_colormap_eval(CDEM_COLORMAP_MAGNITUDE, t);
        cdem_rgba s = cdem_colormap_eval(CDEM_COLORMAP_SIGNED, t);
        /* magnitude: hue falls monotonically from blue (240) to red (0), full saturation */
        double h = hue_deg(m);
        assert_true(h <= prev_h + 1e-9);
        assert_true(fmax(m.r, fmax(m.g, m.b)) == 1.0);
        prev_h = h;
        /* signed: red channel never falls, blue channel never rises */
        assert_true(s.r >= prev_s.r - 1e-12);
        assert_true(s.b <= prev_s.b + 1e-12);
        /* smooth: no jump larger than the steepest slope (4 per unit) allows */
        assert_true(fabs(m.r - prev_m.r) <= 4.0 / n + 1e-12);
        assert_true(fabs(m.g - prev_m.g) <= 4.0 / n + 1e-12);
        assert_true(fabs(m.b - prev_m.b) <= 4.0 / n + 1e-12);
        assert_true(fabs(s.g - prev_s.g) <= M_PI / n + 1e-12);
        prev_m = m;
        prev_s = s;
    }
    /* signed scale eases into its ends: changes slower at the ends than at the centre */
    cdem_rgba c0 = cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 0.5);
    cdem_rgba c1 = cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 0.51);
    cdem_rgba e0 = cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 0.99);
    cdem_rgba e1 = cdem_colormap_eval(CDEM_COLORMAP_SIGNED, 1.0);
    assert_true(fabs(e1.g - e0.g) < 0.05 * fabs(c1.g - c0.g));
}

static void test_colormap_position(void **state) {
    (void)state;
    assert_true(cdem_colormap_position(CDEM_COLORMAP_MAGNITUDE, 2.0, 0.0, 8.0) == 0.25);
    assert_true(cdem_colormap_position(CDEM_COLORMAP_MAGNITUDE, -1.0, 0.0, 8.0) == 0.0);
    assert_true(cdem_colormap_position(CDEM_COLORMAP_MAGNITUDE, 9.0, 0.0, 8.0) == 1.0);
    assert_true(isnan(cdem_colormap_position(CDEM_COLORMAP_MAGNITUDE, NAN, 0.0, 8.0)));
    assert_true(cdem_colormap_position(CDEM_COLORMAP_MAGNITUDE, 3.0, 3.0, 3.0) == 0.0);
    assert_true(cdem_colormap_position(CDEM_COLORMAP_SIGNED, 0.0, 0.0, 0.0) == 0.5);
    assert_true(cdem_colormap_position(CDEM_COLORMAP_SIGNED, -4.0, -4.0, 1.0) == 0.0);
    assert_true(cdem_colormap_position(CDEM_COLORMAP_SIGNED, 1.0, -4.0, 1.0) == 0.625);
}

/* Issue 46: the colour bar's ticks were "%.4g", so a small range far from 0 labelled every
 * tick alike. Labels of neighbouring ticks differ, keep 4 digits where those do (the
 * committed pictures' "81.52", "40.76") and give "0" at 0. */
static void test_colormap_tick_labels_differ(void **state) {
    (void)state;
    char l[5][CDEM_COLORMAP_TICK_CHARS];
    const double ranges[][2] = {{1000.0001, 1000.0005}, {-81.52, 81.52}, {0.0, 2.0},
                                {-3e-9, 3e-9},          {5e6, 5e6 + 1},  {-1e-300, 1e-300}};
    for (size_t r = 0; r < sizeof ranges / sizeof ranges[0]; r++) {
        cdem_colormap_tick_labels(ranges[r][0], ranges[r][1], 5, l);
        printf("    %g .. %g: %s %s %s %s %s\n", ranges[r][0], ranges[r][1], l[0], l[1], l[2], l[3],
               l[4]);
        for (int k = 1; k < 5; k++)
            assert_string_not_equal(l[k], l[k - 1]);
    }
    cdem_colormap_tick_labels(-81.52, 81.52, 5, l);
    assert_string_equal(l[0], "-81.52");
    assert_string_equal(l[1], "-40.76");
    assert_string_equal(l[2], "0");
    cdem_colormap_tick_labels(1000.0001, 1000.0005, 5, l);
    assert_string_equal(l[0], "1000.0001");
    assert_string_equal(l[4], "1000.0005");
    /* one value: one label (the colour bar draws one tick) */
    cdem_colormap_tick_labels(0.0, 0.0, 1, l);
    assert_string_equal(l[0], "0");
}

static void test_colormap_parse_names(void **state) {
    (void)state;
    static const struct {
        const char *name;
        cdem_colormap_kind kind;
    } ok[] = {{"magnitude", CDEM_COLORMAP_MAGNITUDE},
              {"bgr", CDEM_COLORMAP_MAGNITUDE},
              {"signed", CDEM_COLORMAP_SIGNED},
              {"bwr", CDEM_COLORMAP_SIGNED}};
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; k++) {
        cdem_colormap_kind kind = (cdem_colormap_kind)-1;
        cdem_error err;
        cdem_error_clear(&err);
        assert_int_equal(cdem_colormap_parse(ok[k].name, &kind, &err), CDEM_OK);
        assert_int_equal(kind, ok[k].kind);
        assert_string_equal(cdem_colormap_name(kind),
                            kind == CDEM_COLORMAP_SIGNED ? "signed" : "magnitude");
    }
    cdem_colormap_kind kind;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_colormap_parse("jet", &kind, &err), CDEM_ERR_RANGE);
    assert_non_null(strstr(err.msg, "'jet'"));
    assert_non_null(strstr(err.msg, "magnitude"));
    assert_non_null(strstr(err.msg, "signed"));
    assert_int_equal(cdem_colormap_parse(NULL, &kind, &err), CDEM_ERR_RANGE);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_colormap_magnitude_ends_and_middle),
        cmocka_unit_test(test_colormap_signed_ends_and_white_at_zero),
        cmocka_unit_test(test_colormap_monotone_and_smooth),
        cmocka_unit_test(test_colormap_position),
        cmocka_unit_test(test_colormap_parse_names),
        cmocka_unit_test(test_colormap_tick_labels_differ),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
